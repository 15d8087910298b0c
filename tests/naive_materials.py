"""Slow, obviously-correct reference versions of ``sweep.materials`` (direct quadrature).

Nothing here imports ``sweep.materials``: every function transcribes an equation of the paper
(shared/paper/maghami2024-viscoelastic-adhesion.tex, section "Modified power law model" and
appendix A) or a textbook definition, and evaluates it with ``scipy.integrate.quad``.  Spectral
integrals over tau are done in the variable u = ln(tau/tau0) on unit-width pieces, which keeps
every integrand smooth and O(1) wide; times are in units of tau0 and moduli in units of E0
(so C0 = 1, Cinf = k, Einf = 1/k).

Used by tests/test_materials.py.
"""
from __future__ import annotations

import math
import warnings

import numpy as np
from scipy import integrate, special

EPSREL = 1e-13


def _quad(f, a, b, **kw):
    kw.setdefault("epsabs", 0.0)
    kw.setdefault("epsrel", EPSREL)
    kw.setdefault("limit", 400)
    with warnings.catch_warnings():
        # "roundoff error prevents the requested tolerance": quad reports that 1e-13 is out
        # of reach on some pieces; the tests compare values, which is what matters
        warnings.simplefilter("ignore", integrate.IntegrationWarning)
        return integrate.quad(f, a, b, **kw)[0]


def _pieces(a, b, step=1.0):
    """[a, b] cut into pieces of width <= step."""
    n = max(1, int(math.ceil((b - a) / step)))
    return np.linspace(a, b, n + 1)


def _integrate_u(f, lo, hi, extra=()):
    """int_lo^hi f(u) du: break points every 8 units, and every unit within 8 of u = 0 and of
    each ``extra`` point (where the integrands have their features)."""
    pts = [lo, hi, *np.arange(lo, hi, 8.0)]
    for c in (0.0, *extra):
        pts.extend(c + np.arange(-8.0, 8.5, 1.0))
    pts = np.unique([p for p in pts if lo <= p <= hi])
    return sum(_quad(f, a, b) for a, b in zip(pts[:-1], pts[1:]))


# --------------------------------------------------------------------- spectra (paper)

def retardation_spectrum(tau, n, k):
    """Eq. (retspec) in units C0 = 1, tau0 = 1: L = (1 - k)/Gamma(n) tau^n exp(-tau)."""
    return (1.0 - k) / special.gamma(n) * tau ** n * math.exp(-tau)


def relaxation_spectrum(tau, n, k):
    """Eq. (relspec) in units E0 = 1, tau0 = 1: H = (1/k - 1)/Gamma(n) tau^-n exp(-1/tau)."""
    return (1.0 / k - 1.0) / special.gamma(n) * tau ** (-n) * math.exp(-1.0 / tau)


def _u_range_ret(n):
    # L(tau)/tau d tau = tau^(n) e^-tau du: negligible below e^(-40/n) and above ~ n + 60
    return -min(40.0 / n, 700.0), math.log(n + 12.0 * math.sqrt(n) + 60.0)


def _u_range_rel(n):
    # H(tau) d tau with tau = e^u: e^{(1-n) u} exp(-e^{-u}); tau^-n decays for large tau
    return -math.log(n + 12.0 * math.sqrt(n) + 60.0), min(40.0 / n, 700.0)


def creep_mpl_retardation(t, n, k):
    """Chat(t) from eq. (Ct2): Cinf + int L(tau)/tau (1 - exp(-t/tau)) dtau (C0 = 1)."""
    t = float(t)
    if t == 0.0:
        return k
    if math.isinf(t):
        return 1.0

    def f(u):
        tau = math.exp(u)
        return retardation_spectrum(tau, n, k) * -math.expm1(-t / tau)

    lo, hi = _u_range_ret(n)
    return k + _integrate_u(f, lo, hi, extra=(math.log(t),))


def dcreep_mpl_retardation(t, n, k):
    """d Chat/dt = int L(tau)/tau^2 exp(-t/tau) dtau (t > 0)."""
    t = float(t)
    def f(u):
        tau = math.exp(u)
        return retardation_spectrum(tau, n, k) / tau * math.exp(-t / tau)

    lo, hi = _u_range_ret(n)
    return _integrate_u(f, max(lo, math.log(t) - 7.0), hi, extra=(math.log(t),))


def psi_mpl_retardation(T, n, k):
    """Psi(T) = int_0^T Chat = k T + int L(tau)/tau [T - tau (1 - exp(-T/tau))] dtau.

    The bracket tau h(T/tau), h(u) = u - 1 + exp(-u), is evaluated by its Taylor series for
    small u, so the spectral integral has no cancellation.
    """
    T = float(T)

    def h(x):
        if x < 1e-2:
            return sum((-1) ** j * x ** j / math.factorial(j) for j in range(2, 12))
        return x + math.expm1(-x)

    def f(u):
        tau = math.exp(u)
        return retardation_spectrum(tau, n, k) * tau * h(T / tau)

    lo, hi = _u_range_ret(n)
    return k * T + _integrate_u(f, lo, hi, extra=(math.log(T),))


def complex_compliance_mpl_retardation(w, n, k):
    """(C', C'') from eqs. (Dprimeomega), (Dsecomega), w = omega tau0, C0 = 1."""
    w = float(w)
    def f1(u):
        tau = math.exp(u)
        return retardation_spectrum(tau, n, k) / (1.0 + (w * tau) ** 2)

    def f2(u):
        tau = math.exp(u)
        return retardation_spectrum(tau, n, k) * w * tau / (1.0 + (w * tau) ** 2)

    lo, hi = _u_range_ret(n)
    brk = (-math.log(w),)
    return k + _integrate_u(f1, lo, hi, brk), _integrate_u(f2, lo, hi, brk)


def relaxation_mpl_relaxation(t, n, k):
    """Rhat(t) from eq. (Rt2): E0 + int H(tau)/tau exp(-t/tau) dtau (E0 = 1)."""
    t = float(t)
    def f(u):
        tau = math.exp(u)
        return relaxation_spectrum(tau, n, k) * math.exp(-t / tau)

    lo, hi = _u_range_rel(n)
    brk = (math.log(t),) if t > 0 else ()
    return 1.0 + _integrate_u(f, lo, hi, brk)


def complex_modulus_mpl_relaxation(w, n, k):
    """(E', E'') from eqs. (Eprime), (Esecond), w = omega tau0, E0 = 1.

    The integrals are over d tau; in u = ln tau the measure is tau du.
    """
    w = float(w)
    def f1(u):
        tau = math.exp(u)
        return relaxation_spectrum(tau, n, k) * w ** 2 * tau / (1.0 + (w * tau) ** 2) * tau

    def f2(u):
        tau = math.exp(u)
        return relaxation_spectrum(tau, n, k) * w / (1.0 + (w * tau) ** 2) * tau

    lo, hi = _u_range_rel(n)
    brk = (-math.log(w),)
    return 1.0 + _integrate_u(f1, lo, hi, brk), _integrate_u(f2, lo, hi, brk)


# -------------------------------------------------------- generalized exponential integral

def expint_scaled_quad(p, z):
    """exp(z) E_p(z) for Re z >= 0 by quadrature on a rotated contour.

    E_p(z) = int_1^inf exp(-z t) t^-p dt.  With z = |z| e^{i th} and t = 1 + s e^{-i th}
    (Cauchy: the integrand decays in the sector between the real axis and this ray):
    exp(z) E_p(z) = e^{-i th} int_0^inf exp(-|z| s) (1 + s e^{-i th})^-p ds, smooth and
    non-oscillatory; with v = |z| s the integral is done on [0, min(|z|, 1)] and in ln v above.
    """
    r, th = abs(z), np.angle(z)
    ph = np.exp(-1j * th)

    def g(v):
        return np.exp(-v) * (1.0 + (v / r) * ph) ** (-p) * ph / r

    a = min(r, 1.0)
    re = _quad(lambda v: g(v).real, 0.0, a)
    im = _quad(lambda v: g(v).imag, 0.0, a)
    for lo, hi in zip(*(lambda x: (x[:-1], x[1:]))(_pieces(math.log(a), math.log(80.0)))):
        re += _quad(lambda w: (g(math.exp(w)) * math.exp(w)).real, lo, hi)
        im += _quad(lambda w: (g(math.exp(w)) * math.exp(w)).imag, lo, hi)
    return complex(re, im)


# ------------------------------------------------------------------ hereditary integral

def hereditary_residual(R, dC, C0, t):
    """R(t) C(0+) + int_0^t R(t - s) C'(s) ds - 1: zero when C is the creep compliance that
    belongs to the relaxation modulus R (strain under unit step stress, eq. creep-compliance
    inserted into eq. relax).  Quadrature on log-spaced pieces of s (C' may be singular at 0).
    """
    pts = [0.0] + list(np.geomspace(t * 1e-12, t, 25))
    val = R(t) * C0
    for a, b in zip(pts[:-1], pts[1:]):
        val += _quad(lambda s: R(t - s) * dC(s), a, b, limit=200, epsrel=1e-12)
    # the last piece [t/..., t] near s = t is smooth in (t - s); done above
    return val - 1.0


# ------------------------------------------------------------------- Kramers-Kronig

def kk_storage_from_loss(loss, w, E0):
    """E'(w) from the loss modulus by the Kramers-Kronig relation subtracted at w = 0:

        E'(w) - E0 = (2 w^2 / pi) PV int_0^inf E''(x) / (x (w^2 - x^2)) dx.

    The principal value at x = w uses quad's Cauchy weight on [w/2, 2w]:
    1/(x (w^2 - x^2)) = -1/(x (x + w)) * 1/(x - w); the rest is done in ln x.
    """
    def regular(x):
        return loss(x) / (x * (w * w - x * x))

    tot = _quad(lambda x: -loss(x) / (x * (x + w)), 0.5 * w, 2.0 * w, weight="cauchy", wvar=w,
                epsrel=1e-12)
    # left: x in (0, w/2] in ln x (E'' may vanish as slowly as x^0.2: 400 units of ln x);
    # right: [2w, inf) in ln x (the integrand falls at least as x^-3)
    ul, ur = math.log(0.5 * w), math.log(2.0 * w)
    pl = np.concatenate([_pieces(ul - 400.0, ul - 16.0, 8.0), _pieces(ul - 16.0, ul, 2.0)[1:]])
    pr = _pieces(ur, ur + 60.0, 2.0)
    left = sum(_quad(lambda u: regular(math.exp(u)) * math.exp(u), a, b, epsrel=1e-12)
               for a, b in zip(pl[:-1], pl[1:]))
    right = sum(_quad(lambda u: regular(math.exp(u)) * math.exp(u), a, b, epsrel=1e-12)
                for a, b in zip(pr[:-1], pr[1:]))
    return E0 + 2.0 * w * w / math.pi * (tot + left + right)


# ------------------------------------------------------------------------- Prony tables

def kelvin_table_compliance(c, theta, k, w):
    """C(omega)/C0 of Chat = 1 - sum c_i exp(-t/theta_i): k + sum c_i/(1 + i w theta_i)."""
    return k + sum(ci / (1.0 + 1j * w * ti) for ci, ti in zip(c, theta))


def maxwell_table_modulus(e, tau, w):
    """E(omega)/E0 of R/E0 = 1 + sum e_i exp(-t/tau_i): 1 + sum e_i i w tau_i/(1 + i w tau_i)."""
    return 1.0 + sum(ei * 1j * w * ti / (1.0 + 1j * w * ti) for ei, ti in zip(e, tau))
