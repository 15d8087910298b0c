"""The two modified-power-law materials with the same four constants, never mixed
(docs/design.md section 3): ``MPLRetardation`` (the BEM's) and ``MPLRelaxation``."""
from __future__ import annotations

import numpy as np

from ..errors import check_positive, check_range
from ._checks import _check_moduli, _check_n
from .base import _Material
from .closed_forms import _mpl_F, _mpl_one_minus_phi
from .special import _zg
from .tables import (
    _gamma_lattice, _kelvin_chat, _kelvin_psi, _maxwell_rhat, kelvin_to_maxwell, maxwell_to_kelvin,
)


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
