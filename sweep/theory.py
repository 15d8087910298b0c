r"""Analytic theory: Persson-Brener effective surface energy, JKR/Hertz, Gent-Schultz.

All quantities are in the dimensionless units of docs/design.md section 2 (see :mod:`sweep.units`):
contact radius ``a`` in ``a_ref``, indentation in ``d_ref``, load in ``pi dg R``; the
Persson-Brener crack speed is ``vhat = v tau0 / l0``.

Persson-Brener (PB) theory, paper eqs. (PBmodel)/(PBmodel2): with retardation times
``x = tau / tau0`` distributed with a probability density ``p(x)``

.. math::
    \hat\Gamma_{eff} = \frac{1}{1 - (1-k)\,I}, \qquad
    I = \int_0^\infty p(x)\left[\sqrt{1+z^2} - z\right] dx, \qquad
    z = \frac{\hat\Gamma_{eff}}{2\pi\hat v\,x},

where ``p`` is the Gamma(n) density ``x^(n-1) e^(-x) / Gamma(n)`` for the MPL retardation
spectrum, and a sum of weighted deltas for a discrete (Prony/SLS) spectrum.

Numerical method (MPL). With ``c = Gamma_eff / (2 pi vhat)`` the bracket is
``phi(x/c)``, ``phi(y) = y / (1 + sqrt(1+y^2))`` (no cancellation), and an integration by
parts against the regularized incomplete gamma functions ``P(n, x)``, ``Q(n, x) = 1 - P``
gives, with ``y = e^s``,

.. math::
    I = \int_{-\infty}^{\infty} w(s)\,Q(n, c e^s)\,ds,\qquad
    J = 1 - I = \int_{-\infty}^{\infty} w(s)\,P(n, c e^s)\,ds,\qquad
    w(s) = \frac{e^s}{\sqrt{1+e^{2s}}\,(1+\sqrt{1+e^{2s}})}.

Both integrands are analytic in a strip around the real ``s`` axis and decay exponentially at
both ends, so the trapezoidal rule converges geometrically (step 0.2 gives < 1e-13 relative for
n <= 10; the tests compare with ``scipy.integrate.quad`` and with the paper's closed form).
No power-law singularity at ``x = 0`` survives, whatever ``n``. ``J`` and ``I`` are each computed
directly, so ``Gamma_eff = 1 / (k + (1-k) J)`` has no cancellation near ``1/k`` and
``Gamma_eff - 1 = (1-k) I Gamma_eff`` none near 1. The self-consistency is solved for
``ln c`` by safeguarded Newton: ``ln(2 pi vhat) + ln c + ln(k + (1-k) J(c)) = 0`` has a slope
between 1 and 2, so it converges in a few steps.
"""
from __future__ import annotations

import math
from functools import lru_cache

import numpy as np

from .errors import InputError, check_array, check_positive, check_range

__all__ = [
    "pb_gamma_eff",
    "pb_gamma_eff_spectrum",
    "pb_integral",
    "pb_integral_closed_form",
    "jkr_load",
    "jkr_indentation",
    "jkr_contact_radius",
    "jkr_pull_off",
    "jkr_pull_off_point",
    "hertz_load",
    "hertz_indentation",
    "gent_schultz",
    "paper_v_vs_r_fit",
    "maugis_lambda",
    "maugis_dugdale_load",
    "maugis_dugdale_pull_off",
]

#: Largest MPL exponent accepted by the PB routines (the quadrature step is tuned up to it).
N_MAX = 10.0
#: Largest crack speed vhat accepted: Gamma_eff equals 1/k to 1e-16 from vhat ~ 1e50 on, and
#: the quadrature in log time overflows near 1e300.
VHAT_MAX = 1e100
_STEP = 0.2  # trapezoid step in s = ln(x / c)
_TAIL = 36.0  # half-width of the s-window around both 0 and ln(1/c): e^-36 ~ 2e-16
#: x = tau/tau0 beyond which P(n, x) = 1, Q(n, x) = 0 and x^n e^-x = 0 in double precision for
#: every n <= N_MAX (Q(10, 1000) ~ 1e-413): those nodes are not evaluated
_X_DEAD = 1000.0


# --------------------------------------------------------------------------------------------
# validation helpers
# --------------------------------------------------------------------------------------------
def _check_n(n) -> float:
    return check_range("n", n, lo=0.0, hi=N_MAX, lo_open=True)


def _check_vhat(vhat, lo_open: bool = False) -> np.ndarray:
    v = check_array("vhat", vhat, lo=0.0, lo_open=lo_open)
    if v.size and np.max(v) > VHAT_MAX:
        raise InputError(f"vhat must be <= {VHAT_MAX:g} (got {np.max(v):g})")
    return v


def _check_k(k) -> float:
    return check_range("k", k, lo=0.0, hi=1.0, lo_open=True)


def _scalar_or_array(out: np.ndarray, like: np.ndarray):
    return float(out) if like.ndim == 0 else out


# --------------------------------------------------------------------------------------------
# Persson-Brener: the kernel and the MPL integrals
# --------------------------------------------------------------------------------------------
def _kernel_w(s):
    """w(s) = y phi'(y) at y = e^s, with phi'(y) = 1 / (R (1 + R)), R = sqrt(1 + y^2)."""
    y = np.exp(s)
    r = np.hypot(1.0, y)
    return y / (r * (1.0 + r))


def _mpl_integrals(n: float, c: np.ndarray):
    """I(c), J(c) = 1 - I(c) and c dJ/dc for the Gamma(n) spectrum; c is a 1-D array > 0.

    The trapezoid rule in s = ln(x / c) at the step :data:`_STEP` over the window
    [min(-T, -ln c - T), max(T, -ln c + T)], T = :data:`_TAIL`, taken on the lattice
    t = ln x = j _STEP that every c shares (:func:`_mpl_lattice`): the incomplete gamma
    functions, the costly part, are evaluated once per n at the lattice's nodes, and each c
    weighs them by the kernel w(t - ln c) = y / (R (1 + R)), y = e^t / c (a product, no
    exponential per node). The sum runs over the whole lattice: the nodes beyond a c's own
    window weigh less than e^-T ~ 2e-16 of it. Against a window anchored at each c (the
    trapezoid rule on another lattice: the sums differ by its aliasing, e^-49 here) the
    integrals agree to 2e-15 relative, at a third to a quarter of the time (n 0.22-3, 681
    values of c over 34 decades). Where ln c lies beyond +-:data:`_LATTICE_LNC` (the
    lattice's e^t would overflow) the window anchored at each such c is kept
    (:func:`_mpl_integrals_windowed`, on those c alone: one window as wide as the widest
    overflowed where a speed near 0 and one near VHAT_MAX were solved together).
    """
    lnc = np.log(c)
    far = ~(np.abs(lnc) <= _LATTICE_LNC)
    if np.any(far):             # those on their own windows, the others on the lattice
        out = [np.empty(c.size) for _ in range(3)]
        for rows, integrals in ((far, _mpl_integrals_windowed), (~far, _mpl_integrals)):
            if np.any(rows):
                for o, x in zip(out, integrals(n, c[rows])):
                    o[rows] = x
        return tuple(out)
    lo = float(min(np.min(lnc) - _TAIL, -_TAIL))
    hi = float(max(np.max(lnc) + _TAIL, _TAIL))
    # the lattice's ends in blocks of _LATTICE_BLOCK nodes: Newton's shrinking set of c
    # (sweep.theory._solve_gamma) shares one lattice
    j_lo = int(math.floor(lo / _STEP / _LATTICE_BLOCK)) * _LATTICE_BLOCK
    j_hi = int(math.ceil(hi / _STEP / _LATTICE_BLOCK)) * _LATTICE_BLOCK
    e_t, p, q, xp = _mpl_lattice(float(n), j_lo, j_hi)
    y = e_t[None, :] / c[:, None]
    r = np.hypot(1.0, y)
    w = _STEP * y / (r * (1.0 + r))
    return np.sum(w * q, axis=1), np.sum(w * p, axis=1), np.sum(w * xp, axis=1)


#: :func:`_mpl_integrals` takes the shared lattice where |ln c| is at most this (its nodes
#: reach ln c +- _TAIL, and e^t overflows beyond 709) ...
_LATTICE_LNC = 600.0
#: ... and extends the lattice in blocks of this many nodes
_LATTICE_BLOCK = 64


@lru_cache(maxsize=16)
def _mpl_lattice(n: float, j_lo: int, j_hi: int):
    """(e^t, P(n, e^t), Q(n, e^t), e^t p(n, e^t)) on the lattice t = j _STEP, j_lo <= j <=
    j_hi (read-only; :func:`_gamma_nodes`)."""
    t = _STEP * np.arange(j_lo, j_hi + 1)
    x = np.exp(t)
    p, q, xp = _gamma_nodes(n, x, t)
    for a in (x, p, q, xp):
        a.flags.writeable = False
    return x, p, q, xp


def _gamma_nodes(n: float, x: np.ndarray, ln_x: np.ndarray):
    """P(n, x), Q(n, x) and x p(x) = x^n e^-x / Gamma(n) (the Newton slope's integrand) at
    the nodes ``x`` (``ln_x`` their logarithms), one incomplete gamma function each:
    ``Q(n, x)`` above ``max(1, n)``, ``P(n, x)`` at or below it, the other as its complement
    (what scipy's own ``gammainc`` does above that point, so ``J`` there is the same number;
    below it ``Q = 1 - P >= Q(n, max(1, n))`` loses nothing that counts). Beyond ``x =``
    :data:`_X_DEAD` the nodes are ``P = 1``, ``Q = 0`` and ``x p(x) = 0`` in double precision
    and are not evaluated."""
    from scipy.special import gammainc, gammaincc, gammaln  # lazy: not on a BEM scene's path
    live = x < _X_DEAD
    lower = live & (x <= max(1.0, n))
    upper = live & ~lower
    p = np.ones_like(x)
    q = np.zeros_like(x)
    p[lower] = gammainc(n, x[lower])
    q[upper] = gammaincc(n, x[upper])
    q[lower] = 1.0 - p[lower]
    p[upper] = 1.0 - q[upper]
    xp = np.zeros_like(x)
    with np.errstate(under="ignore"):
        np.exp(n * ln_x - x - gammaln(n), out=xp, where=live)
    return p, q, xp


def _mpl_integrals_windowed(n: float, c: np.ndarray):
    """:func:`_mpl_integrals` on a window anchored at each c (its incomplete gamma functions
    evaluated at every node of every c): for ln c beyond the shared lattice's reach."""
    lnc = np.log(c)
    s0 = np.minimum(-_TAIL, -lnc - _TAIL)
    s1 = np.maximum(_TAIL, -lnc + _TAIL)
    m = int(np.ceil(np.max(s1 - s0) / _STEP)) + 1
    s = s0[:, None] + _STEP * np.arange(m)[None, :]
    w = _STEP * _kernel_w(s)
    with np.errstate(over="ignore"):        # x beyond 1e308: a node beyond _X_DEAD, as it is
        x = c[:, None] * np.exp(s)
    p, q, xp = _gamma_nodes(n, x, lnc[:, None] + s)
    return np.sum(w * q, axis=1), np.sum(w * p, axis=1), np.sum(w * xp, axis=1)


def _spectrum_integrals(weights: np.ndarray, times: np.ndarray, c: np.ndarray):
    """I, J, c dJ/dc for a discrete spectrum (weights sum to 1, times in [0, inf])."""
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        y = times[None, :] / c[:, None]
        r = np.hypot(1.0, y)
        phi = np.where(np.isinf(y), 1.0, y / (1.0 + r))
        psi = (1.0 + 1.0 / (r + y)) / (1.0 + r)  # 1 - phi without cancellation
        y_dphi = np.where(np.isinf(y), 0.0, y / (r * (1.0 + r)))
    return phi @ weights, psi @ weights, y_dphi @ weights


def _solve_gamma(vhat: np.ndarray, k: float, integrals) -> np.ndarray:
    """Solve G = 1 / (k + (1-k) J(G / (2 pi vhat))) for every vhat (1-D array >= 0)."""
    out = np.ones_like(vhat)
    todo = vhat > 0.0
    if k == 1.0 or not np.any(todo):
        return out
    v = vhat[todo]
    ln2pv = np.log(2.0 * np.pi * v)
    lo = -ln2pv  # G = 1
    hi = -ln2pv - np.log(k)  # G = 1/k
    u = lo.copy()
    active = np.arange(v.size)  # rows whose Newton step was still above 1e-14
    for _ in range(100):
        ua = u[active]
        _, big_j, c_dj = integrals(np.exp(ua))
        d = k + (1.0 - k) * big_j
        phi = ln2pv[active] + ua + np.log(d)
        slope = 1.0 + (1.0 - k) * c_dj / d
        lo_a = np.where(phi <= 0.0, ua, lo[active])
        hi_a = np.where(phi >= 0.0, ua, hi[active])
        u_new = ua - phi / slope
        outside = (u_new < lo_a) | (u_new > hi_a)
        u_new = np.where(outside, 0.5 * (lo_a + hi_a), u_new)
        step = np.abs(u_new - ua)
        u[active], lo[active], hi[active] = u_new, lo_a, hi_a
        active = active[step > 1e-14 * np.maximum(1.0, np.abs(u_new))]
        if not active.size:
            break
    _, big_j, _ = integrals(np.exp(u))
    out[todo] = 1.0 / (k + (1.0 - k) * big_j)
    return out


def pb_integral(n, vhat, gamma):
    r"""The Persson-Brener integral of the MPL retardation spectrum, by quadrature.

    .. math::
        I(n, \hat v, \hat\Gamma) = \int_0^\infty \frac{x^{n-1}e^{-x}}{\Gamma(n)}
        \left[\sqrt{1+z^2} - z\right] dx,\qquad z = \frac{\hat\Gamma}{2\pi\hat v x}

    Parameters
    ----------
    n : float
        MPL exponent, in (0, 10].
    vhat : float or array_like
        Crack speed ``v tau0 / l0`` (> 0).
    gamma : float or array_like
        Normalized effective surface energy inside ``z`` (> 0); broadcast with ``vhat``.

    Returns
    -------
    float or ndarray
        ``I`` in (0, 1), relative accuracy about 1e-13.
    """
    n = _check_n(n)
    vhat = _check_vhat(vhat, lo_open=True)
    gamma = check_array("gamma", gamma, lo=0.0, lo_open=True)
    v, g = np.broadcast_arrays(vhat, gamma)
    c = (g / (2.0 * np.pi * v)).ravel()
    big_i = _mpl_integrals(n, c)[0] if c.size else c
    return _scalar_or_array(big_i.reshape(v.shape), v)


def pb_gamma_eff(n, k, vhat):
    r"""Persson-Brener normalized effective surface energy of the MPL retardation spectrum.

    Solves the paper's eq. (PBmodel2)

    .. math::
        \hat\Gamma_{eff} = \left[1 - (1-k)\,I(n, \hat v, \hat\Gamma_{eff})\right]^{-1},
        \qquad \hat\Gamma_{eff} = \Delta\gamma_{eff}/\Delta\gamma_0,

    with :func:`pb_integral` (module docstring: method). Limits: 1 as ``vhat -> 0`` with slope
    ``(1-k) pi n`` (:math:`\hat\Gamma_{eff} - 1 = (1-k)\pi n\hat v + O(\hat v^3)`), and
    ``1/k`` as ``vhat -> inf``.

    Parameters
    ----------
    n : float
        MPL exponent, in (0, 10] (the retardation times ``tau/tau0`` are Gamma(n)-distributed).
    k : float
        ``E0 / Einf``, in (0, 1].
    vhat : float or array_like
        Crack speed ``v tau0 / l0`` (>= 0; 0 gives exactly 1).

    Returns
    -------
    float or ndarray
        ``Gamma_eff`` (scalar for scalar ``vhat``). Measured in the tests for vhat in
        [1e-6, 1e12], n in [0.05, 3], k in [1e-5, 0.5]: agreement with an independent
        brentq + ``quad`` solve within 1.3e-11 relative (limited by the reference, which forms
        ``1 - (1-k) I``), and halving the quadrature step changes it by < 1e-13.
    """
    n = _check_n(n)
    k = _check_k(k)
    v = _check_vhat(vhat)
    out = _solve_gamma(v.ravel(), k, lambda c: _mpl_integrals(n, c))
    return _scalar_or_array(out.reshape(v.shape), v)


def pb_gamma_eff_spectrum(weights, times, k, vhat):
    r"""Persson-Brener effective surface energy of a discrete retardation spectrum.

    .. math::
        \hat\Gamma_{eff} = \left[1 - (1-k)\sum_i w_i
        \left(\sqrt{1+z_i^2} - z_i\right)\right]^{-1},\qquad
        z_i = \frac{\hat\Gamma_{eff}}{2\pi\hat v\,x_i}

    The SLS is ``weights=[1], times=[1]``. For a Prony series of the normalized creep
    compliance ``Chat(t) = 1 - sum_i c_i exp(-t / tau_i)`` (``sum c_i = 1 - k``) pass
    ``weights = c_i``, ``times = tau_i / tau0`` and ``k = 1 - sum(c_i)``.

    Parameters
    ----------
    weights : array_like
        Relative weights of the retardation times (>= 0, positive sum; normalized to sum 1).
    times : array_like
        Retardation times in units of ``tau0`` (>= 0; ``np.inf`` is a mode that never
        relaxes, i.e. a glassy constant: its bracket is 1).
    k : float
        ``E0 / Einf``, in (0, 1].
    vhat : float or array_like
        Crack speed ``v tau0 / l0`` (>= 0).

    Returns
    -------
    float or ndarray
        ``Gamma_eff`` for each ``vhat``.
    """
    w = check_array("weights", weights, lo=0.0).ravel()
    try:
        t = np.asarray(times, dtype=float).ravel()
    except (TypeError, ValueError):
        raise InputError(f"times must be numbers (got {times!r})") from None
    if w.size == 0 or w.size != t.size:
        raise InputError(
            f"weights and times must be non-empty and of equal length (got {w.size} and {t.size})"
        )
    if np.any(np.isnan(t)) or np.any(t < 0.0):
        raise InputError(f"times must be in [0, inf] (got {t!r})")
    total = float(np.sum(w))
    if not total > 0.0:
        raise InputError("weights must have a positive sum (got 0)")
    w = w / total
    k = _check_k(k)
    v = _check_vhat(vhat)
    out = _solve_gamma(v.ravel(), k, lambda c: _spectrum_integrals(w, t, c))
    return _scalar_or_array(out.reshape(v.shape), v)


# --------------------------------------------------------------------------------------------
# Appendix B closed form (cross-check only)
# --------------------------------------------------------------------------------------------
def _hyp1f2(a: float, b1: float, b2: float, z: float):
    """Power series of 1F2(a; b1, b2; z); returns (sum, largest |term|)."""
    term, total, biggest = 1.0, 1.0, 1.0
    for j in range(10000):
        term *= (a + j) / ((b1 + j) * (b2 + j) * (j + 1.0)) * z
        total += term
        biggest = max(biggest, abs(term))
        if j > 4 and abs(term) <= 1e-17 * abs(total):
            return total, biggest
    raise RuntimeError("1F2 series did not converge")  # pragma: no cover


def _closed_form_scalar(n: float, v: float, g: float, rtol: float) -> float:
    from scipy.special import gamma as gamma_fn, rgamma  # lazy: not on a BEM scene's path
    z = -((g / (4.0 * math.pi * v)) ** 2)
    f0, m0 = _hyp1f2(-0.5, 0.5 - 0.5 * n, 1.0 - 0.5 * n, z)
    f1, m1 = _hyp1f2(0.5 * (n - 1.0), 0.5, 1.0 + 0.5 * n, z)
    f2, m2 = _hyp1f2(0.5 * n, 1.5, 1.5 + 0.5 * n, z)
    r1 = rgamma(0.5) * rgamma(1.0 + 0.5 * n)  # regularization of the last two
    r2 = rgamma(1.5) * rgamma(1.5 + 0.5 * n)
    pref = 2.0 ** (-3.0 - 2.0 * n) * math.pi ** (-1.5 - n) / ((n - 1.0) * v)
    c1 = 4.0 ** (1.0 + n) * math.pi ** (0.5 + n)
    c2 = 2.0 * math.pi * (g / v) ** n
    a1 = 4.0 * math.pi * v * gamma_fn(1.0 - 0.5 * n) * r1
    a2 = g * gamma_fn(1.5 - 0.5 * n) * r2
    b0 = 2.0 * (n - 1.0) * math.pi * v
    value = pref * (-c1 * (g - b0 * f0) + c2 * (a1 * f1 + a2 * f2))
    # rounding bound: every piece carries ~eps relative error of its largest partial term
    scale = abs(pref) * (c1 * (g + abs(b0) * m0) + c2 * (abs(a1) * m1 + abs(a2) * m2))
    if not math.isfinite(value) or 4.0 * np.finfo(float).eps * scale > rtol * abs(value):
        return math.nan
    return value


def pb_integral_closed_form(n, vhat, gamma, rtol: float = 1e-8):
    r"""The integral ``I`` of :func:`pb_integral` by the paper's Appendix-B closed form.

    .. math::
        I = \frac{2^{-3-2n}\pi^{-3/2-n}}{(n-1)\hat v}\Big\{-4^{1+n}\pi^{1/2+n}
        \big[\hat\Gamma - 2(n-1)\pi\hat v\,{}_1F_2(-\tfrac12; \tfrac{1-n}{2}, 1-\tfrac n2; -w^2)
        \big] + 2\pi(\hat\Gamma/\hat v)^n\big[4\pi\hat v\,\Gamma(1-\tfrac n2)\,
        {}_1\tilde F_2(\tfrac{n-1}{2}; \tfrac12, \tfrac{2+n}{2}; -w^2)
        + \hat\Gamma\,\Gamma(\tfrac32-\tfrac n2)\,
        {}_1\tilde F_2(\tfrac n2; \tfrac32, \tfrac{3+n}{2}; -w^2)\big]\Big\},
        \quad w = \frac{\hat\Gamma}{4\pi\hat v}

    (``1F2~`` regularized). A cross-check only: the hypergeometric functions are summed as
    power series in double precision, whose terms grow like ``e^(2w)`` while ``I`` decays like
    ``1/w``; the terms cancel, so accuracy is lost for large ``w``. Measured relative
    difference from the quadrature, ``2w = Gamma/(2 pi vhat)``: < 1e-13 for ``2w <= 3``,
    < 1e-11 at 10, 1e-9 at 15, 1e-7 to 1e-6 at 20 (n in {0.05, 0.8, 1.6, 2.5}). A rounding
    bound, ``4 eps`` times the sum of the magnitudes of the pieces and of their largest series
    terms (it exceeded the measured error in every case tried), is evaluated and ``nan`` is
    returned where it exceeds ``rtol``. Integer ``n`` is not supported (removable poles: the
    ``1/(n-1)`` prefactor, the gamma functions and the lower parameters of the first 1F2);
    near-integer ``n`` loses digits (n = 1.001: 5e-9 at ``2w = 10``) and is flagged ``nan``
    by the same bound once that loss exceeds ``rtol``.

    Parameters
    ----------
    n : float
        MPL exponent in (0, 10], not an integer.
    vhat, gamma : float or array_like
        As in :func:`pb_integral` (> 0), broadcast together.
    rtol : float
        Largest acceptable estimated relative rounding error (> 0).

    Returns
    -------
    float or ndarray
        ``I``, or ``nan`` where the series is not accurate to ``rtol``.
    """
    n = _check_n(n)
    if n == round(n):
        raise InputError(
            f"n must not be an integer for the closed form (got {n:g}); use pb_integral"
        )
    rtol = check_positive("rtol", rtol)
    vhat = _check_vhat(vhat, lo_open=True)
    gamma = check_array("gamma", gamma, lo=0.0, lo_open=True)
    v, g = np.broadcast_arrays(vhat, gamma)
    out = np.array(
        [_closed_form_scalar(n, vi, gi, rtol) for vi, gi in zip(v.ravel(), g.ravel())],
        dtype=float,
    )
    return _scalar_or_array(out.reshape(v.shape), v)


# --------------------------------------------------------------------------------------------
# JKR and Hertz (units of docs/design.md section 2: a in a_ref, delta in d_ref, P in pi dg R)
# --------------------------------------------------------------------------------------------
_SQRT2 = math.sqrt(2.0)
#: contact radius at the force-controlled pull-off, dP/da = 0: a^(3/2) = 3 sqrt(2) / 4
A_PULL_OFF_FORCE = (3.0 * _SQRT2 / 4.0) ** (2.0 / 3.0)
#: contact radius at the displacement-controlled (fixed grips) pull-off, d delta/da = 0
A_PULL_OFF_GRIPS = 0.5


def hertz_load(a):
    r"""Hertz load of a rigid sphere: :math:`\hat P = \tfrac43 \hat a^3` (units pi dg R)."""
    a = check_array("a", a, lo=0.0)
    return (4.0 / 3.0) * a[()] ** 3


def hertz_indentation(a):
    r"""Hertz indentation: :math:`\hat\delta = \hat a^2` (units d_ref)."""
    a = check_array("a", a, lo=0.0)
    return a[()] ** 2


def jkr_load(a):
    r"""JKR load as a function of the contact radius (load in pi dg R, a in a_ref).

    .. math:: \hat P = \tfrac43 \hat a^3 - 2\sqrt2\,\hat a^{3/2}

    Negative is tensile.
    """
    a = check_array("a", a, lo=0.0)[()]
    return (4.0 / 3.0) * a**3 - 2.0 * _SQRT2 * a**1.5


def jkr_indentation(a):
    r"""JKR indentation as a function of the contact radius (delta in d_ref, a in a_ref).

    .. math:: \hat\delta = \hat a^2 - \sqrt{2\hat a}
    """
    a = check_array("a", a, lo=0.0)[()]
    return a**2 - np.sqrt(2.0 * a)


def jkr_contact_radius(load=None, indentation=None):
    r"""JKR contact radius on the stable branch, from the load or from the indentation.

    Give exactly one of ``load`` or ``indentation``.

    * Load control: the branch ``a >= (3 sqrt2 / 4)^(2/3) ~ 1.040`` (beyond the pull-off,
      ``load >= -1.5``), in closed form: with ``u = a^(3/2)``,
      :math:`\tfrac43 u^2 - 2\sqrt2 u - \hat P = 0`,
      :math:`u = \tfrac38\left(2\sqrt2 + \sqrt{8 + \tfrac{16}{3}\hat P}\right)`.
    * Displacement control: the branch ``a >= 1/2`` (``indentation >= -3/4``); the quartic
      :math:`b^4 - \sqrt2\,b = \hat\delta`, ``b = sqrt(a)``, is solved by Newton from the right
      (convex and increasing there, so monotone convergence).

    Returns
    -------
    float or ndarray
        ``a`` in units of ``a_ref``.
    """
    if (load is None) == (indentation is None):
        raise InputError("give exactly one of load or indentation")
    if load is not None:
        p = check_array("load", load, lo=-1.5)
        u = 0.375 * (2.0 * _SQRT2 + np.sqrt(np.maximum(8.0 + 16.0 * p / 3.0, 0.0)))
        return u[()] ** (2.0 / 3.0)
    d = check_array("indentation", indentation, lo=-0.75)
    b_min = 2.0**-0.5  # sqrt(1/2)
    b = np.maximum(np.sqrt(np.abs(d)) + 1.0, 1.5)  # right of the root: b^4 - sqrt2 b >= d
    for _ in range(100):
        f = b**4 - _SQRT2 * b - d
        fp = 4.0 * b**3 - _SQRT2
        step = f / fp
        b = np.maximum(b - step, b_min)
        if np.all(np.abs(step) <= 1e-15 * b):
            break
    return (b**2)[()]


def jkr_pull_off():
    """JKR pull-off force under load control, 1.5 (units pi dg R): ``P_JKR = 3/2 pi dg R``."""
    return 1.5


def jkr_pull_off_point(control: str = "force"):
    r"""The JKR point where the contact becomes unstable: ``(a, load, indentation)``.

    * ``"force"`` (load control): :math:`d\hat P/d\hat a = 0`, :math:`a^{3/2} = 3\sqrt2/4`,
      ``load = -3/2``, ``indentation = a^2 - sqrt(2a)``.
    * ``"displacement"`` (fixed grips): :math:`d\hat\delta/d\hat a = 0`, ``a = 1/2``,
      ``indentation = -3/4``, ``load = -5/6``.
    """
    if control not in ("force", "displacement"):
        raise InputError(f"control must be one of force, displacement (got {control!r})")
    a = A_PULL_OFF_FORCE if control == "force" else A_PULL_OFF_GRIPS
    return float(a), float(jkr_load(a)), float(jkr_indentation(a))


# --------------------------------------------------------------------------------------------
# rate-dependent adhesion laws
# --------------------------------------------------------------------------------------------
def gent_schultz(v, v0, xi):
    r"""Gent-Schultz law, the paper's eq. (GS), normalized.

    .. math:: \frac{\Delta\gamma_{eff}}{\Delta\gamma_0} = 1 + \left(\frac{v}{v_0}\right)^\xi

    Parameters
    ----------
    v : float or array_like
        Crack speed (>= 0), any unit.
    v0 : float
        Reference speed (> 0), same unit as ``v``.
    xi : float
        Exponent (> 0).
    """
    v = check_array("v", v, lo=0.0)
    v0 = check_positive("v0", v0)
    xi = check_positive("xi", xi)
    return 1.0 + (v[()] / v0) ** xi


def paper_v_vs_r_fit(rhat_pb, prefactor: float = 2.887, exponent: float = 1.171):
    r"""The PAPER's empirical fit of crack speed at pull-off against unloading rate.

    .. math:: \hat v = 2.887\,\hat r_{PB}^{1.171}

    eq. (Vvsr) of the paper, fitted there to its BEM results at mu = 3.24 (+-15 %). This is the
    paper's number, exposed for comparison only; the project computes its own fit from its own
    runs. ``rhat_pb = r tau0 / d_ref`` (see :func:`sweep.units.rhat_pb` for why).

    Parameters
    ----------
    rhat_pb : float or array_like
        Unloading rate ``r tau0 / d_ref`` (>= 0).
    prefactor, exponent : float
        The fit constants (> 0); defaults are the paper's.

    Returns
    -------
    float or ndarray
        ``vhat = v tau0 / l0``.
    """
    r = check_array("rhat_pb", rhat_pb, lo=0.0)
    prefactor = check_positive("prefactor", prefactor)
    exponent = check_positive("exponent", exponent)
    return prefactor * r[()] ** exponent


# --------------------------------------------------------------------------------------------
# Maugis-Dugdale (a guide across the Tabor range; units of docs/design.md section 2 on output)
# --------------------------------------------------------------------------------------------
#: lambda / mu when the Dugdale stress equals the largest Lennard-Jones tension (see below)
MAUGIS_LAMBDA_PER_MU = (32.0 / (9.0 * math.sqrt(3.0))) * (9.0 / (16.0 * math.pi)) ** (1.0 / 3.0)
#: Maugis' contact radius A = a (K / (pi dg R^2))^(1/3), K = 4 E*/3, per a / a_ref
_MAUGIS_A_PER_A = (4.0 / 3.0) ** (1.0 / 3.0)


def maugis_lambda(mu):
    r"""Maugis' transition parameter lambda equivalent to the Tabor parameter mu.

    Maugis (J. Colloid Interface Sci. 150, 243 (1992)) defines
    :math:`\lambda = 2\sigma_0 (R / (\pi\,\Delta\gamma K^2))^{1/3}`, ``K = 4 E*/3``. Taking the
    Dugdale stress ``sigma_0`` equal to the largest Lennard-Jones tension,
    :math:`\sigma_0 = 16\Delta\gamma / (9\sqrt3\,h_0)` (so that the Dugdale range
    ``dg / sigma_0 = 0.974 h0``), and Tabor's :math:`\mu = (R\Delta\gamma^2/(E^{*2}h_0^3))^{1/3}`:

    .. math:: \lambda = \frac{32}{9\sqrt3}\left(\frac{9}{16\pi}\right)^{1/3}\mu \approx 1.1570\,\mu

    (Johnson & Greenwood, J. Colloid Interface Sci. 192, 326 (1997), the factor 1.16).
    """
    mu = check_array("mu", mu, lo=0.0, lo_open=True)
    return MAUGIS_LAMBDA_PER_MU * mu[()]


def _md_lhs(s, A, lam):
    """Left side of Maugis' eq. (the Dugdale-zone closure) with s = sqrt(m^2 - 1), m = c/a."""
    at = np.arctan(s)
    m2 = 1.0 + s * s
    return (0.5 * lam * A * A * (s + (m2 - 2.0) * at)
            + (4.0 * lam * lam * A / 3.0) * (s * at - np.sqrt(m2) + 1.0))


def _md_load_zero_radius(lam):
    """Maugis load at A -> 0 (Dugdale disk of radius C = m A, no contact): -lam pi C^2 / 2.

    The closure tends to ``lam pi C^2 / 4 + (4 lam^2 / 3)(pi/2 - 1) C = 1`` (positive root).
    """
    b = (4.0 * lam * lam / 3.0) * (0.5 * math.pi - 1.0)
    qa = 0.25 * lam * math.pi
    C = 2.0 / (b + math.sqrt(b * b + 4.0 * qa))
    return -0.5 * lam * math.pi * C * C


def maugis_dugdale_load(A, lam):
    r"""Maugis-Dugdale load at Maugis' contact radius ``A`` (Maugis' units, P in pi dg R).

    Solves the closure for ``m = c/a`` (the Dugdale zone spans a < r < c)

    .. math::
        \frac{\lambda A^2}{2}\left[\sqrt{m^2-1} + (m^2-2)\arctan\sqrt{m^2-1}\right]
        + \frac{4\lambda^2 A}{3}\left[\sqrt{m^2-1}\arctan\sqrt{m^2-1} - m + 1\right] = 1

    (monotone in m, one root by brentq) and returns
    :math:`\bar P = A^3 - \lambda A^2\left[\sqrt{m^2-1} + m^2\arctan\sqrt{m^2-1}\right]`;
    ``A = 0`` gives the closed-form limit. ``A = a / a_ref * (4/3)^(1/3)``; the load unit
    ``pi dg R`` is the project's.
    """
    from scipy.optimize import brentq

    A = float(A)
    lam = float(lam)
    if A <= 0.0:
        return _md_load_zero_radius(lam)
    hi = 1.0
    while _md_lhs(hi, A, lam) < 1.0:
        hi *= 2.0
    s = brentq(lambda x: _md_lhs(x, A, lam) - 1.0, 0.0, hi, xtol=1e-15, rtol=1e-15)
    return A**3 - lam * A * A * (s + (1.0 + s * s) * math.atan(s))


def maugis_dugdale_pull_off(lam):
    r"""Maugis-Dugdale pull-off under load control: ``(pull_off, a)``.

    ``pull_off = -min_A P(A)`` over the whole branch A >= 0 (units pi dg R; 2 in the DMT
    limit lambda -> 0, 3/2 in the JKR limit lambda -> inf) and the contact radius there in
    units of a_ref (it tends to 0 as lambda -> 0 and to the JKR 1.040 as lambda -> inf).
    Found by a scan of A on [0, 4] and a bounded Brent refinement around the scan's minimum.

    Asymptotics (derived in tests/test_theory.py): ``2 - 1.7175 lambda^(3/2)`` for small
    lambda (the A -> 0 end of the branch), ``1.5 + (1.5^(2/3)/8) / lambda^2 = 1.5 + 0.1638 /
    lambda^2`` for large lambda. Values: 1.9506 (lambda 0.1), 1.6007 (1), 1.5063 (5),
    1.5016 (10).
    """
    from scipy.optimize import minimize_scalar

    lam = check_positive("lam", lam)
    grid = np.linspace(0.0, 4.0, 161)
    loads = np.array([maugis_dugdale_load(A, lam) for A in grid])
    i = int(np.argmin(loads))
    best_A, best_P = float(grid[i]), float(loads[i])
    lo, hi = grid[max(i - 1, 0)], grid[min(i + 1, grid.size - 1)]
    res = minimize_scalar(lambda A: maugis_dugdale_load(A, lam), bounds=(lo, hi),
                          method="bounded", options={"xatol": 1e-10})
    if res.fun < best_P:
        best_A, best_P = float(res.x), float(res.fun)
    return -best_P, best_A / _MAUGIS_A_PER_A
