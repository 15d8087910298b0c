"""Dimensionless <-> physical conversions (docs/design.md section 2): the one place that owns them.

Units of the dimensionless problem ("hats"), for a sphere of radius ``R`` on a half-space of
relaxed plane-strain modulus ``E0* = E0 / (1 - nu^2)`` with work of adhesion ``dg``:

============================  ==================================================
quantity                      unit
============================  ==================================================
in-plane length (r, a, l0)    ``a_ref = (pi R^2 dg / E0*)^(1/3)``
normal length (h, u, delta)   ``d_ref = (pi^2 dg^2 R / E0*^2)^(1/3) = a_ref^2/R``
traction                      ``p_ref = E0* d_ref / a_ref``
load                          ``load_ref = pi dg R``
time                          ``tau0`` (MPL characteristic / SLS retardation time)
============================  ==================================================

Tabor parameter ``mu = (R dg^2 / (E0*^2 h0^3))^(1/3)``; everything dimensionless that depends
on the interface is a function of ``mu`` alone (module-level functions below).
:class:`PhysicalScale` converts between SI values and these units.

Rates and speeds (three different normalisations, never mix them):

* ``rate`` (the paper's r-hat): indenter speed ``r tau0 / h0``; in the dimensionless scene
  ``d delta / dt = -rate * h0_hat``.
* ``rhat_pb``: ``r tau0 / d_ref = rate * h0_hat``, the abscissa of the paper's fit
  ``vhat = 2.887 rhat_PB^1.171`` (docs/design.md section 2 explains the choice).
* crack speed ``v_a = -da/dt`` in ``a_ref / tau0`` (BEM output) versus the Persson-Brener
  ``vhat = v tau0 / l0 = v_a / l0_hat``.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .errors import check_array, check_positive, check_range

#: The paper's coefficient relating the PB critical stress to the LJ maximum tension,
#: ``sigma_c = alpha sigma_0`` (section "Persson and Brener ...").
ALPHA_PB = math.pi / 9.0

_PI13 = math.pi ** (1.0 / 3.0)
_PI23 = math.pi ** (2.0 / 3.0)


def _check_alpha(alpha) -> float:
    return check_positive("alpha", alpha)


def l0_coefficient(alpha: float = ALPHA_PB) -> float:
    r"""The constant ``c_l`` of the process-zone length, dimensionless.

    .. math:: c_l = \frac{243}{256\,\pi\,\alpha^2}, \qquad
              l_0 = c_l\,\frac{E_0^* h_0^2}{\Delta\gamma_0}

    Parameters
    ----------
    alpha : float
        ``sigma_c / sigma_0`` (> 0), default pi/9.
    """
    alpha = _check_alpha(alpha)
    return 243.0 / (256.0 * math.pi * alpha**2)


# --------------------------------------------------------------------------------------------
# functions of the Tabor parameter alone (dimensionless scene)
# --------------------------------------------------------------------------------------------
def h0_hat(mu):
    r"""LJ equilibrium distance in units of ``d_ref``.

    .. math:: \hat h_0 = \frac{1}{\pi^{2/3}\mu}

    Parameters
    ----------
    mu : float
        Tabor parameter (> 0).
    """
    mu = check_positive("mu", mu)
    return 1.0 / (_PI23 * mu)


def sigma0_hat(mu):
    r"""Largest LJ tension in units of ``p_ref``.

    .. math:: \hat\sigma_0 = \frac{16\,\mu}{9\sqrt{3}\,\pi^{1/3}}
    """
    mu = check_positive("mu", mu)
    return 16.0 * mu / (9.0 * math.sqrt(3.0) * _PI13)


def lj_prefactor(mu):
    r"""Prefactor of the LJ traction law in units of ``p_ref``.

    .. math:: \hat\sigma(h) = -\frac{8\mu}{3\pi^{1/3}}
              \left[\left(\frac{h_0}{h}\right)^3 - \left(\frac{h_0}{h}\right)^9\right]
    """
    mu = check_positive("mu", mu)
    return 8.0 * mu / (3.0 * _PI13)


def l0_hat(mu, alpha: float = ALPHA_PB):
    r"""Persson-Brener process-zone length ``l0`` in units of ``a_ref``.

    .. math:: \hat l_0 = \frac{l_0}{a_{ref}} = \frac{c_l}{\pi^{1/3}\mu^2},\qquad
              l_0 = \frac{E_0^*\Delta\gamma_0}{\pi(\alpha\sigma_0)^2}

    (about ``1.693 / mu^2`` for alpha = pi/9).
    """
    mu = check_positive("mu", mu)
    return l0_coefficient(alpha) / (_PI13 * mu**2)


def vhat_from_crack_speed(v_a, mu, alpha: float = ALPHA_PB):
    r"""Persson-Brener crack speed from a BEM crack speed.

    .. math:: \hat v = \frac{v\,\tau_0}{l_0} = \hat v_a\,\frac{a_{ref}}{l_0}
              = \frac{\hat v_a}{\hat l_0(\mu)}

    Parameters
    ----------
    v_a : float or array_like
        Crack speed ``-da/dt`` in units of ``a_ref / tau0``.
    mu : float
        Tabor parameter.
    """
    return np.asarray(v_a, dtype=float)[()] / l0_hat(mu, alpha)


def crack_speed_from_vhat(vhat, mu, alpha: float = ALPHA_PB):
    """Inverse of :func:`vhat_from_crack_speed`: ``v_a = vhat * l0_hat(mu)`` (a_ref / tau0)."""
    return np.asarray(vhat, dtype=float)[()] * l0_hat(mu, alpha)


def rhat_pb(rate, mu):
    r"""The unloading rate on the abscissa of the paper's fit ``vhat = 2.887 rhat_PB^1.171``.

    .. math:: \hat r_{PB} = \frac{r\,\tau_0}{d_{ref}} = \widehat{rate}\;\hat h_0
              = \frac{\widehat{rate}}{\pi^{2/3}\mu}

    The paper writes ``r tau / l0``, but ``r tau0 / l0`` is not fixed by the dimensionless
    scene; the first author's scripts use ``rate * h0_hat`` i.e. ``r tau0 / d_ref`` (the
    indenter speed in normal units), which is the definition used here (docs/design.md section 2).

    Parameters
    ----------
    rate : float or array_like
        The paper's r-hat, ``r tau0 / h0`` (>= 0).
    mu : float
        Tabor parameter.
    """
    rate = check_array("rate", rate, lo=0.0)
    return rate[()] * h0_hat(mu)


def rate_from_rhat_pb(rhat, mu):
    """Inverse of :func:`rhat_pb`: ``rate = rhat_PB / h0_hat(mu) = rhat_PB * mu * pi^(2/3)``."""
    rhat = check_array("rhat_pb", rhat, lo=0.0)
    return rhat[()] / h0_hat(mu)


def delta0_from_h0_units(delta_over_h0, mu):
    r"""Indentation given in units of ``h0`` -> units of ``d_ref``.

    .. math:: \hat\delta = (\delta/h_0)\,\hat h_0(\mu)
    """
    return np.asarray(delta_over_h0, dtype=float)[()] * h0_hat(mu)


def delta0_to_h0_units(delta_hat, mu):
    """Inverse of :func:`delta0_from_h0_units`: ``delta / h0 = delta_hat / h0_hat(mu)``."""
    return np.asarray(delta_hat, dtype=float)[()] / h0_hat(mu)


# --------------------------------------------------------------------------------------------
# physical scale
# --------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class PhysicalScale:
    r"""SI scales of one sphere / substrate / interface combination.

    Parameters
    ----------
    R : float
        Sphere radius [m].
    dg : float
        Work of adhesion ``Delta gamma_0`` [J/m^2].
    E0_star : float
        Relaxed plane-strain modulus ``E0 / (1 - nu^2)`` [Pa].
    h0 : float
        LJ equilibrium distance [m].
    alpha : float
        ``sigma_c / sigma_0`` for the Persson-Brener length ``l0`` (default pi/9).

    Notes
    -----
    Conversions ``x_hat = x / unit``: in-plane lengths by :attr:`a_ref`, normal lengths by
    :attr:`d_ref`, tractions by :attr:`p_ref`, loads by :attr:`load_ref`, times by ``tau0``
    (a material property, passed to the rate and speed methods).
    """

    R: float
    dg: float
    E0_star: float
    h0: float
    alpha: float = ALPHA_PB

    def __post_init__(self):
        for name in ("R", "dg", "E0_star", "h0", "alpha"):
            object.__setattr__(self, name, check_positive(name, getattr(self, name)))

    @classmethod
    def from_moduli(cls, R, dg, E0, nu, h0, alpha: float = ALPHA_PB) -> "PhysicalScale":
        """Build from Young's relaxed modulus ``E0`` [Pa] and Poisson's ratio ``nu`` in [0, 0.5]."""
        E0 = check_positive("E0", E0)
        nu = check_range("nu", nu, lo=0.0, hi=0.5)
        return cls(R=R, dg=dg, E0_star=E0 / (1.0 - nu**2), h0=h0, alpha=alpha)

    # ---- units -------------------------------------------------------------------------------
    @property
    def a_ref(self) -> float:
        r"""In-plane length unit [m]: :math:`a_{ref} = (\pi R^2 \Delta\gamma_0 / E_0^*)^{1/3}`."""
        return (math.pi * self.R**2 * self.dg / self.E0_star) ** (1.0 / 3.0)

    @property
    def d_ref(self) -> float:
        r"""Normal length unit [m]: :math:`d_{ref} = a_{ref}^2 / R`."""
        return self.a_ref**2 / self.R

    @property
    def p_ref(self) -> float:
        r"""Traction unit [Pa]: :math:`p_{ref} = E_0^* d_{ref} / a_{ref}`."""
        return self.E0_star * self.d_ref / self.a_ref

    @property
    def load_ref(self) -> float:
        r"""Load unit [N]: :math:`\pi \Delta\gamma_0 R` (the JKR pull-off is 1.5 of it)."""
        return math.pi * self.dg * self.R

    # ---- interface -----------------------------------------------------------------------------
    @property
    def mu(self) -> float:
        r"""Tabor parameter :math:`\mu = (R\Delta\gamma_0^2 / (E_0^{*2} h_0^3))^{1/3}`."""
        return (self.R * self.dg**2 / (self.E0_star**2 * self.h0**3)) ** (1.0 / 3.0)

    @property
    def h0_hat(self) -> float:
        """``h0 / d_ref`` (equals :func:`h0_hat` of :attr:`mu`)."""
        return self.h0 / self.d_ref

    @property
    def sigma0(self) -> float:
        r"""Largest LJ tension [Pa]: :math:`\sigma_0 = 16\Delta\gamma_0 / (9\sqrt3\,h_0)`."""
        return 16.0 * self.dg / (9.0 * math.sqrt(3.0) * self.h0)

    @property
    def l0(self) -> float:
        r"""Persson-Brener process-zone length [m].

        .. math:: l_0 = \frac{E_0^*\Delta\gamma_0}{\pi(\alpha\sigma_0)^2}
        """
        return self.E0_star * self.dg / (math.pi * (self.alpha * self.sigma0) ** 2)

    # ---- lengths, loads, tractions -------------------------------------------------------------
    def radius_hat(self, r):
        """In-plane length [m] -> units of a_ref."""
        return np.asarray(r, dtype=float)[()] / self.a_ref

    def radius_physical(self, r_hat):
        """In-plane length in a_ref -> [m]."""
        return np.asarray(r_hat, dtype=float)[()] * self.a_ref

    def normal_hat(self, d):
        """Normal length (gap, displacement, indentation) [m] -> units of d_ref."""
        return np.asarray(d, dtype=float)[()] / self.d_ref

    def normal_physical(self, d_hat):
        """Normal length in d_ref -> [m]."""
        return np.asarray(d_hat, dtype=float)[()] * self.d_ref

    def load_hat(self, P):
        """Load [N] -> units of pi dg R."""
        return np.asarray(P, dtype=float)[()] / self.load_ref

    def load_physical(self, P_hat):
        """Load in pi dg R -> [N]."""
        return np.asarray(P_hat, dtype=float)[()] * self.load_ref

    def traction_hat(self, sigma):
        """Traction [Pa] -> units of p_ref."""
        return np.asarray(sigma, dtype=float)[()] / self.p_ref

    def traction_physical(self, sigma_hat):
        """Traction in p_ref -> [Pa]."""
        return np.asarray(sigma_hat, dtype=float)[()] * self.p_ref

    # ---- times, rates, speeds (tau0 [s] is the material's) -------------------------------------
    @staticmethod
    def time_hat(t, tau0):
        """Time [s] -> units of tau0 [s]."""
        return np.asarray(t, dtype=float)[()] / check_positive("tau0", tau0)

    @staticmethod
    def time_physical(t_hat, tau0):
        """Time in tau0 -> [s]."""
        return np.asarray(t_hat, dtype=float)[()] * check_positive("tau0", tau0)

    def rate_hat(self, r, tau0):
        r"""Indenter speed [m/s] -> the paper's r-hat, :math:`r\tau_0/h_0`."""
        return np.asarray(r, dtype=float)[()] * check_positive("tau0", tau0) / self.h0

    def rate_physical(self, rate_hat, tau0):
        r"""The paper's r-hat -> indenter speed [m/s], :math:`r = \hat r h_0/\tau_0`."""
        return np.asarray(rate_hat, dtype=float)[()] * self.h0 / check_positive("tau0", tau0)

    def rhat_pb(self, r, tau0):
        r"""Indenter speed [m/s] -> :math:`\hat r_{PB} = r\tau_0/d_{ref}` (see :func:`rhat_pb`)."""
        return np.asarray(r, dtype=float)[()] * check_positive("tau0", tau0) / self.d_ref

    def crack_speed_hat(self, v, tau0):
        r"""Crack speed [m/s] -> BEM units :math:`a_{ref}/\tau_0`."""
        return np.asarray(v, dtype=float)[()] * check_positive("tau0", tau0) / self.a_ref

    def crack_speed_physical(self, v_a, tau0):
        r"""Crack speed in :math:`a_{ref}/\tau_0` -> [m/s]."""
        return np.asarray(v_a, dtype=float)[()] * self.a_ref / check_positive("tau0", tau0)

    def vhat_pb(self, v, tau0):
        r"""Crack speed [m/s] -> Persson-Brener :math:`\hat v = v\tau_0/l_0`."""
        return np.asarray(v, dtype=float)[()] * check_positive("tau0", tau0) / self.l0

    def crack_speed_from_vhat_pb(self, vhat, tau0):
        r"""Persson-Brener :math:`\hat v` -> crack speed [m/s], :math:`v = \hat v l_0/\tau_0`."""
        return np.asarray(vhat, dtype=float)[()] * self.l0 / check_positive("tau0", tau0)
