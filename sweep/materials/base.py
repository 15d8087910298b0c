"""The common base of the materials: moduli, k, tau0, and the methods every material
shares (creep, relaxation, complex moduli, ``.prony``)."""
from __future__ import annotations

import math

from ..errors import InputError, check_int, check_range
from ._checks import MAX_WINDOW_DECADES, _as_time_array
from .fitting import fit_prony


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
