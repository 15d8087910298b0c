"""``Prony``: a material given as a Kelvin or Wiechert (generalized Maxwell) table."""
from __future__ import annotations

import numpy as np

from ..errors import InputError, check_choice, check_positive
from .base import _Material
from .tables import (
    _kelvin_chat, _kelvin_psi, _maxwell_rhat, _merge_times, kelvin_to_maxwell, maxwell_to_kelvin,
)


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
