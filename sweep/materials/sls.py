"""The standard linear solid (Kelvin form, tau0 = retardation time)."""
from __future__ import annotations

import numpy as np

from ..errors import check_positive, check_range
from ._checks import _check_moduli
from .base import _Material
from .closed_forms import _h


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
