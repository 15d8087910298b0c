"""``PronySeries``: a fitted Kelvin approximation of Chat on a time window, the input of the
O(N M) hereditary recursion (docs/design.md section 4)."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ._checks import _as_time_array
from .tables import _kelvin_chat, _kelvin_psi


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
