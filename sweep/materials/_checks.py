"""Validation helpers and limits shared by the material modules (private)."""
from __future__ import annotations

import numpy as np

from ..errors import InputError, check_positive, check_range


N_MAX = 20.0          # largest MPL exponent accepted (tested up to 3; checked to 20)
MAX_WINDOW_DECADES = 100   # widest Prony window (a scene needs < 25 decades; 50 take ~5 s)
_EULER = 0.57721566490153286


def _as_time_array(name: str, t):
    """float64 array of times >= 0 (+inf allowed), plus a flag 'input was a scalar'."""
    scalar = np.ndim(t) == 0
    try:
        arr = np.asarray(t, dtype=float)
    except (TypeError, ValueError):
        raise InputError(f"{name} must be numbers (got {t!r})") from None
    if arr.size:
        if np.isnan(arr).any():
            raise InputError(f"{name} must be >= 0 and not NaN (got NaN)")
        lo = float(arr.min())
        if lo < 0.0:
            raise InputError(f"{name} must be >= 0 (got {lo:.6g})")
    return arr, scalar


def _check_moduli(E0, Einf):
    E0 = check_positive("E0", E0)
    Einf = check_positive("Einf", Einf)
    if Einf < E0:
        raise InputError(
            f"Einf must be >= E0 = {E0:.6g} (k = E0/Einf in (0, 1]) (got {Einf:.6g})"
        )
    return E0, Einf


def _check_n(n):
    return check_range("n", n, 0.0, N_MAX, lo_open=True)
