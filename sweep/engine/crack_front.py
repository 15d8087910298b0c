r"""Crack-front model: displacement-controlled unloading of a JKR contact with a rate-dependent
work of adhesion ``Gamma(v)``.

For contacts much larger than the process zone ``l0`` (large Tabor parameter, e.g. the PDMS
experiment at mu ~ 100) the BEM mesh is unaffordable; the classical alternative (Greenwood &
Johnson, Barquins & Maugis) treats the contact edge as a crack in a relaxed elastic half-space
whose energy release rate ``G`` must equal a rate-dependent fracture energy ``Gamma(v)``.
Units of docs/design.md section 2 (:mod:`sweep.units`): ``a`` in ``a_ref``, ``delta`` in ``d_ref``,
``P`` in ``pi dg R`` (positive compressive), ``t`` in ``tau0``, crack speed
``v = -da/dt`` in ``a_ref / tau0``; ``g = G / dg`` and ``Gamma`` normalized by ``dg``.

Elastic field (Hertz + flat punch with the relaxed modulus):

.. math::
    \hat P = 2\hat a\hat\delta - \tfrac23 \hat a^3, \qquad
    g(\hat a, \hat\delta) = \frac{(\hat a^2 - \hat\delta)^2}{2\hat a},

(``g = 1`` is the JKR curve ``delta = a^2 - sqrt(2a)``, ``P = 4/3 a^3 - 2 sqrt2 a^(3/2)``).
The indentation falls at the unloading rate, ``delta(t) = delta0 - rate * h0_hat * t`` (rate is
the paper's r-hat), and the edge recedes at the speed that makes the crack critical:

.. math:: \frac{d\hat a}{d\hat t} = -V\!\left(g(\hat a, \hat\delta(t))\right),
          \qquad \Gamma(V(g)) = g,\quad V = 0 \text{ for } g \le \Gamma(0).

The start is the relaxed JKR equilibrium (``g = 1``); while ``g <= Gamma(0)`` the edge is
pinned (closed form), then the ODE is integrated with scipy's implicit Radau method (the
problem is stiff: ``dV/dg`` is huge when ``Gamma`` is nearly rate independent) with the
analytic Jacobian ``-V'(g) dg/da``, ``dg/da = (a^2 - delta)(3 a^2 + delta) / (2 a^2)``.
The pull-off is the first tensile load minimum: bracketed by three accepted states whose middle
load is the smallest, then located as the smallest ``P(a(t), delta(t))`` on the integrator's
dense output of the two steps around it; the run stops there (``stop="pulloff"``) or when the
contact has nearly vanished.

Two numerical hazards of a stiff law, and how :func:`unload` meets them (issue: an elastic bulk
with a Gent-Schultz zone of ``v0 = 1e14`` gave 1.4918 for at least 1.5, status ok, on one
processor and not on another).

* ``g = Gamma(0)`` is a barrier the solution never crosses once the edge moves: there ``V = 0``
  and ``dg/dt = -(a^2 - delta) d(delta)/dt / a > 0`` under unloading. Radau's error estimate is
  filtered by ``(I - h gamma J)^-1`` with the stiff Jacobian of the step's start (``|J| ~ 1e5``);
  with ``V = 0`` below the barrier, a step that lands there (the collocation solved with the
  end stage pinned) is not stiff at its end and its error is underestimated by that factor:
  a step of ``a`` 1.157 -> 0.988 was accepted with an error norm of 0.45, the edge then stayed
  pinned until ``g`` came back to 1 past the load minimum (a = 1.040), and the event fired
  there. The right-hand side therefore continues ``V`` oddly below the barrier,
  ``V(g) = -V(2 Gamma(0) - g)``, which leaves the exact solution unchanged (it never goes
  there) and makes ``g = Gamma(0)`` attracting from both sides, so an overshoot is pulled back
  instead of pinned; and a state accepted further below the barrier than the step's tolerance
  allows (:data:`THRESHOLD_CROSSING`) fails the run with the reason, never an ``ok`` row.
* Where ``Gamma - Gamma(0)`` at the pull-off (here ``(v/v0)^xi ~ 1e-7``) is not much larger
  than the integrator's resolution of ``g`` (``|dg/da| atol``), ``V(g)`` at a state is as
  uncertain as ``g``, and the sign of ``dP/dt = 2 V (a^2 - delta) + 2 a d(delta)/dt`` near the
  minimum is noise: the former event ``dP/dt = 0`` on the dense output fired up to 1e-3 a_ref
  off the minimum. The load itself depends on ``a`` smoothly, so the minimum of ``P`` is
  bracketed and located on ``P`` (its value is then as accurate as ``a``), and the crack speed
  reported is the one that makes ``dP/dt`` vanish there, ``a |d(delta)/dt| / (a^2 - delta)``.

Pull-off under displacement control. With ``Gamma = dg`` (rate independent) the contact follows
the JKR curve; the tensile load is largest, ``|P| = 1.5`` (``3/2 pi dg R``), at
``a = (3 sqrt2/4)^(2/3) = 1.040``, where the contact is still stable under fixed grips; it
becomes unstable only at ``a = 1/2``, ``P = -5/6`` (``d delta/da = 0``). The pull-off force
(the largest tension, as the paper and the BEM define it) is therefore 1.5 under displacement
control as under load control, provided ``a0 > 1.040``; ``-5/6`` is the load at which the
sphere jumps off. For a constant ``Gamma = c dg`` reached after pinning (``Gamma(0) = c``) the
closed form is ``1.5 c`` for ``a0 >= 1.040 c^(1/3)`` and
``2 sqrt(2c) a0^(3/2) - 4/3 a0^3`` (the load at depinning) for ``a0/c^(1/3)`` in
``[1/2, 1.040]``: tested in ``tests/engine/test_crack_front.py``.

Rate laws (:class:`GentSchultzLaw`, :class:`PerssonBrenerLaw`, :class:`ProcessZoneLaw`) map
``v`` to ``Gamma`` and back; :func:`unload` runs one unloading; :func:`simulate_crack` runs a
:class:`sweep.Scene` with the law of its material and interface (:func:`scene_law`) and returns
a :class:`sweep.Result` row.

Bulk and process zone together. A scene with a process zone (``pz_law`` "gent-schultz",
``Gamma_pz(v) = dg (1 + (v/pz_v0)^pz_xi)`` for ``v > 0``, ``dg`` for ``v <= 0``) opens with
the product

.. math:: \Gamma(v) = \Gamma_{pz}(v)\,\hat\Gamma_{PB}(\hat v), \qquad \hat v = v/l_0,

the process zone's work of separation times the bulk's Persson-Brener amplification of the
scene's material (:class:`ProcessZoneLaw`). The product is the Persson-Brener argument with
the rate-independent dg of the crack tip replaced by the process zone's ``Gamma_pz``: the bulk
multiplies whatever energy the tip consumes (the form of Gent-Schultz's own factorization,
``Gamma = dg_0 (1 + phi(a_T v))``, and of Persson-Brener's eq. with a rate-dependent
``dg_0``); it holds where the process zone is small against the bulk's dissipative region,
and the length l0 in ``vhat`` stays that of the rate-independent LJ zone (a first-order
model). An elastic bulk (k = 1) gives ``Gamma = Gamma_pz`` (:class:`GentSchultzLaw`).
"""
from __future__ import annotations

import cmath
import math
import time
from bisect import bisect_right
from dataclasses import dataclass, field
from functools import lru_cache

import numpy as np
# LAPACK's LU for Radau (_lapack_lu): loaded with scipy.linalg on every path (kernels.blas),
# so imported here rather than at each of the integrator's many calls (1.2 us each)
from scipy.linalg.lapack import dgetrf, dgetrs, zgetrf, zgetrs

from .. import units
from . import budget
from ..errors import (NUMERICAL_ERRORS, InputError, check_choice, check_positive, check_range,
                      is_internal_error)
from ..scene import MATERIALS, Numerics, Result, SceneTable
from ..theory import (A_PULL_OFF_FORCE, jkr_contact_radius, jkr_indentation, pb_gamma_eff,
                     pb_gamma_eff_spectrum)

__all__ = ["GentSchultzLaw", "PerssonBrenerLaw", "ProcessZoneLaw", "CrackFrontSolution",
           "unload", "energy_release_rate", "crack_front_load", "pb_law_for_scene", "scene_law",
           "simulate_crack", "constant_gamma_pull_off", "answers", "FIXED_GRIP_A_MIN"]

#: 1/k - 1 at or below which the crack-front model is the elastic JKR contact at the constant
#: Gamma = dg / sqrt(k), the geometric middle of Gamma(v) in [dg, dg/k]: its pull-off is then
#: within 1/sqrt(k) - 1 (at most 2.5 %, its ``error_estimate``) of any rate's, while the
#: integration of a law that steep stalls (k = 0.998 at rate 1e9) or steps over the load
#: minimum (k = 0.98 at rate 1e-4, a0 = 15: 1.452 for at least 1.5)
NEARLY_ELASTIC = 0.05
#: a process zone on a (nearly) elastic bulk whose term (v/pz_v0)^pz_xi at ten times the crack
#: speed of the constant-Gamma contact is at most this is none: the closed form answers the
#: scene, the term added to its error estimate (the Gent-Schultz law alone stiffens as pz_v0
#: grows: at pz_v0 = 1e25 a_ref/tau0 the integrator stalled until the time budget ended it)
NEGLIGIBLE_PROCESS_ZONE = 1e-9
#: the smallest Gent-Schultz exponent the crack-front model follows: below it the term
#: (v/pz_v0)^pz_xi is nearly 1 at every speed (a step of Gamma at v = 0+) and the law's
#: inverse, V(g) = pz_v0 (g - 1)^(1/pz_xi), overflows (pz_xi 3e-4 and below had failed with
#: "integrator: OverflowError: math range error"; 1e-3 runs)
PZ_XI_MIN = 1e-3
#: how far below Gamma(0) (in step tolerances of the contact radius, carried to g by dg/da) an
#: accepted state of :func:`unload` may lie before the run is failed: the exact solution stays
#: at or above Gamma(0) once the edge moves. Measured with the odd continuation of V: at most
#: 2e-4 on the PB fixture's 25 scenes and 72 process-zone scenes (k 1 and 0.1, rates 1e-4 to
#: 1e4, pz_v0 0.1 to 1e20); without it, the two steps that jumped over the crack's motion in
#: the v0 = 1e14 scene of the module docstring: 5e5 and 3e6
THRESHOLD_CROSSING = 10.0
#: smallest initial contact radius (a_ref) of the crack-front model: below it a JKR contact
#: is not stable under fixed grip (the model's physical limit, not a numerical one)
FIXED_GRIP_A_MIN = 0.5
#: the indentation of that contact (d_ref), -0.75: the smallest the model starts from
FIXED_GRIP_DELTA_MIN = float(jkr_indentation(FIXED_GRIP_A_MIN))


def negligible_zone_term(scene, crack_speed: float) -> float:
    """The Gent-Schultz term (v/pz_v0)^pz_xi of ``scene``'s process zone at ten times
    ``crack_speed`` (a_ref/tau0; where NaN, the indentation speed rate h0): a zone whose term
    is at most :data:`NEGLIGIBLE_PROCESS_ZONE` is none, the term added to the row's estimate
    (here on a nearly elastic bulk, and by ``auto`` on an elastic one)."""
    v = crack_speed if math.isfinite(crack_speed) else scene.rate * units.h0_hat(scene.mu)
    return float((10.0 * v / scene.pz_v0) ** scene.pz_xi)


# ============================================================================ elastic field

def crack_front_load(a, delta):
    r"""Load of the Hertz + flat-punch field, :math:`\hat P = 2\hat a\hat\delta - \tfrac23\hat a^3`."""
    a = np.asarray(a, dtype=float)
    return (2.0 * a * delta - (2.0 / 3.0) * a**3)[()]


def energy_release_rate(a, delta):
    r"""Normalized energy release rate at the edge, :math:`g = (\hat a^2-\hat\delta)^2/(2\hat a)`."""
    a = np.asarray(a, dtype=float)
    return ((a * a - delta) ** 2 / (2.0 * a))[()]


def constant_gamma_pull_off(a0, c=1.0):
    r"""Closed-form pull-off (units pi dg R) of a contact that starts in the relaxed JKR state
    at radius ``a0`` and opens with a rate-independent ``Gamma = c dg`` (``c >= 1``).

    ``1.5 c`` if ``a0 >= 1.040 c^(1/3)``; else the load at depinning,
    ``2 sqrt(2c) a0^(3/2) - 4/3 a0^3``, valid down to ``a0 = c^(1/3)/2`` (the fixed-grip
    instability; smaller contacts jump off at depinning with the same formula).
    """
    a0 = check_positive("a0", a0)
    c = check_range("c", c, lo=1.0)
    if a0 >= A_PULL_OFF_FORCE * c ** (1.0 / 3.0):
        return 1.5 * c
    return 2.0 * math.sqrt(2.0 * c) * a0**1.5 - (4.0 / 3.0) * a0**3


# ============================================================================ rate laws

class GentSchultzLaw:
    r"""Gent-Schultz fracture energy, the paper's eq. (GS):
    :math:`\Gamma(v) = c\,[1 + (v/v_0)^\xi]` (normalized by dg).

    Parameters
    ----------
    v0 : float
        Reference crack speed (> 0), in the model's speed unit (a_ref / tau0 in :func:`unload`).
    xi : float
        Exponent (> 0).
    c : float
        ``Gamma(0)`` (>= 1; 1 is the paper's law, larger values pin the edge until g = c).
    """

    def __init__(self, v0, xi, c=1.0):
        self.v0 = check_positive("v0", v0)
        self.xi = check_positive("xi", xi)
        self.c = check_range("c", c, lo=1.0)
        self.g_threshold = self.c
        self.g_max = math.inf

    def gamma(self, v):
        """``Gamma(v)``; ``c`` at ``v <= 0`` (a closing crack consumes no rate term)."""
        v = np.maximum(np.asarray(v, dtype=float), 0.0)
        with np.errstate(over="ignore"):        # inf beyond floats: a toughness no load meets
            return (self.c * (1.0 + (v / self.v0) ** self.xi))[()]

    def speed(self, g):
        """``V(g)`` and ``dV/dg`` (0 where ``g <= c``; inf where ``V`` overflows: a trial
        stage of the integrator far off the solution, without a warning)."""
        x = np.maximum(np.asarray(g, dtype=float) / self.c - 1.0, 0.0)
        with np.errstate(over="ignore"):
            v = self.v0 * x ** (1.0 / self.xi)
        with np.errstate(divide="ignore", invalid="ignore"):
            dv = np.where(x > 0, v / (self.xi * x * self.c), 0.0)
        return v[()], dv[()]

    def __repr__(self):
        return f"GentSchultzLaw(v0={self.v0:g}, xi={self.xi:g}, c={self.c:g})"


def _spectrum(material) -> tuple:
    """(weights, times) of the discrete retardation spectrum of "sls" or a table (times in
    tau0; :func:`sweep.theory.pb_gamma_eff_spectrum` normalizes the weights); () for "mpl"."""
    if isinstance(material, SceneTable):
        return material.weights, material.times
    return ((1.0,), (1.0,)) if material == "sls" else ()


@lru_cache(maxsize=32)
def _pb_table(kind: str, n: float, k: float, weights: tuple, times: tuple):
    """log(vhat) as a monotone function of log(Gamma - 1) for the PB law (vhat = v tau0/l0)."""
    from scipy.interpolate import PchipInterpolator  # lazy: not on a BEM scene's path
    vh = np.logspace(-10.0, 24.0, 681)
    if kind == "mpl":
        g = pb_gamma_eff(n, k, vh)
    else:
        g = pb_gamma_eff_spectrum(list(weights), list(times), k, vh)
    keep = np.concatenate([[True], np.diff(g) > 0]) & (g > 1.0) & (g < 1.0 / k)
    vh, g = vh[keep], g[keep]
    x, y = np.log(g - 1.0), np.log(vh)
    ok = np.concatenate([[True], np.diff(x) > 1e-12])     # strictly increasing abscissa
    vh.flags.writeable = g.flags.writeable = False        # shared by every law of the cache
    return (PchipInterpolator(x[ok], y[ok]), float(g[0]), float(g[-1]), float(vh[0]),
            float(vh[-1]), vh, g)


class PerssonBrenerLaw:
    r"""Persson-Brener fracture energy of a retardation spectrum,
    :math:`\Gamma(v) = \hat\Gamma_{eff}(\hat v)`, ``vhat = v / l0`` (:mod:`sweep.theory`).

    The inverse ``V(g)`` is a monotone (PCHIP) interpolation of ``ln vhat`` against
    ``ln(Gamma - 1)`` on ``vhat`` in ``[1e-10, 1e24]`` (20 points per decade); below it the
    linear regime ``Gamma - 1 = q vhat``; at or above the largest tabulated ``Gamma`` (close to
    ``1/k``) the speed is capped at the table's end (``capped`` in the solution then).

    Parameters
    ----------
    n, k : float
        MPL exponent and ``E0/Einf`` (material "mpl"); for "sls" and a table ``n`` is
        ignored.
    l0 : float
        Process-zone length in the model's length unit (``l0_hat(mu)`` in a_ref), > 0.
    material : {"mpl", "sls"} or SceneTable
        A table (:class:`sweep.scene.SceneTable`) gives its discrete retardation spectrum,
        Kelvin weights ``c_i`` at times ``theta_i`` (tau0), to
        :func:`sweep.theory.pb_gamma_eff_spectrum`; its ``k`` must be the table's.
    """

    def __init__(self, n, k, l0, material="mpl"):
        if not isinstance(material, SceneTable):
            material = check_choice("material", material, MATERIALS)
        self.k = check_range("k", k, 0.0, 1.0, lo_open=True)
        self.n = check_positive("n", n)
        self.l0 = check_positive("l0", l0)
        self.material = material
        if self.k == 1.0:
            raise InputError("k must be < 1 for a rate-dependent Persson-Brener law (got 1)")
        self._spectrum = _spectrum(material)
        if isinstance(material, SceneTable) and not math.isclose(self.k, material.k,
                                                                 rel_tol=1e-9):
            raise InputError(f"k must be the table's {material.k:.10g} for material "
                             f"{material} (got {self.k:g})")
        if material == "mpl":
            tab = _pb_table("mpl", self.n, self.k, (), ())
        else:
            tab = _pb_table("spectrum", 0.0, self.k, *self._spectrum)
        self._spline, self._g_lo, self._g_hi, self._v_lo, self._v_hi, self._vh, self._g = tab
        self._dspline = self._spline.derivative()
        self._q = (self._g_lo - 1.0) / self._v_lo      # linear-regime slope (Gamma-1)/vhat
        # the splines' breakpoints and coefficients as Python lists: the integrator asks for
        # one g at a time, where scipy's PPoly call costs ~20 us of overhead (_speed_scalar)
        self._xs = self._spline.x.tolist()
        self._cs = self._spline.c.T.tolist()
        self._dcs = self._dspline.c.T.tolist()
        self.g_threshold = 1.0
        self.g_max = 1.0 / self.k
        self.v_cap = self._v_hi * self.l0

    def gamma(self, v):
        v = np.asarray(v, dtype=float) / self.l0
        if self.material == "mpl":
            return pb_gamma_eff(self.n, self.k, v)
        return pb_gamma_eff_spectrum(*self._spectrum, self.k, v)

    def speed(self, g):
        """``V(g)`` [l0 / tau0 units times l0] and ``dV/dg``."""
        if isinstance(g, float):          # a Python or numpy scalar: the integrator's call
            return self._speed_scalar(float(g))
        g = np.asarray(g, dtype=float)
        x = g - 1.0
        v = np.zeros(g.shape)
        dv = np.zeros(g.shape)
        lin = (x > 0) & (g < self._g_lo)
        v[lin] = x[lin] / self._q
        dv[lin] = 1.0 / self._q
        mid = (g >= self._g_lo) & (g < self._g_hi)
        if mid.any():
            lx = np.log(x[mid])
            vm = np.exp(self._spline(lx))
            v[mid] = vm
            dv[mid] = vm * self._dspline(lx) / x[mid]
        top = g >= self._g_hi
        v[top] = self._v_hi
        return (v * self.l0)[()], (dv * self.l0)[()]

    def _speed_scalar(self, g):
        """:meth:`speed` of one ``g``: the same spline pieces, evaluated as scipy's PPoly
        does (the interval with ``x[i] <= ln(g - 1) < x[i+1]``, clipped to the end pieces;
        the sum ``c3 + c2 s + c1 s^2 + c0 s^3`` term by term), in Python floats."""
        x = g - 1.0
        if not x > 0.0:
            return 0.0, 0.0
        if g < self._g_lo:
            return x / self._q * self.l0, 1.0 / self._q * self.l0
        if g >= self._g_hi:
            return self._v_hi * self.l0, 0.0
        lx = math.log(x)
        xs = self._xs
        i = min(max(bisect_right(xs, lx) - 1, 0), len(xs) - 2)
        s = lx - xs[i]
        s2 = s * s
        c0, c1, c2, c3 = self._cs[i]
        vm = math.exp(c3 + c2 * s + c1 * s2 + c0 * (s2 * s))
        d0, d1, d2 = self._dcs[i]
        dv = vm * (d2 + d1 * s + d0 * s2) / x
        return vm * self.l0, dv * self.l0

    def table(self):
        """The law's table: crack speeds (in the law's unit, ``vhat l0``) and ``Gamma`` there,
        with the slope ``(Gamma - 1)/v`` of the linear regime below it (read only)."""
        return self._vh * self.l0, self._g, self._q / self.l0

    def __repr__(self):
        return (f"PerssonBrenerLaw(material={self.material!r}, n={self.n:g}, k={self.k:g}, "
                f"l0={self.l0:g})")


#: points per decade of crack speed of :class:`ProcessZoneLaw`'s table, and the most decades it
#: extends beyond the Persson-Brener table to hold the process zone's own range
PZ_TABLE_PER_DECADE = 20
PZ_TABLE_MAX_DECADES = 200


class ProcessZoneLaw:
    r"""A process zone in a viscoelastic bulk: :math:`\Gamma(v) = \Gamma_{pz}(v)\,
    \hat\Gamma_{PB}(v/l_0)` (normalized by dg; the module docstring argues the product).

    The inverse ``V(g)`` is a monotone (PCHIP) interpolation of ``ln v`` against
    ``ln(Gamma - 1)`` on the bulk's table (:meth:`PerssonBrenerLaw.table`), extended below it
    with the bulk's linear regime and above it with its last value (~1/k) until the process
    zone's term spans ``(v/v0)^xi`` from 1e-10 to 1e8 (at most
    :data:`PZ_TABLE_MAX_DECADES` decades); beyond the table ``ln v`` continues linearly in
    ``ln(Gamma - 1)`` with the end slopes (the power laws both terms tend to). ``Gamma(0) = 1``:
    the edge is never pinned; no speed cap.

    Parameters
    ----------
    process_zone : GentSchultzLaw
        ``Gamma_pz(v)`` with ``c = 1`` (the rate-independent dg at zero speed).
    bulk : PerssonBrenerLaw
        The bulk's Persson-Brener law (same speed unit).
    """

    def __init__(self, process_zone, bulk):
        if process_zone.c != 1.0:
            raise InputError(f"c must be 1 for a process zone in a viscoelastic bulk "
                             f"(got {process_zone.c:g})")
        self.process_zone, self.bulk = process_zone, bulk
        self.g_threshold = 1.0
        self.g_max = math.inf
        self._spline, self._dspline, self._ends = _product_table(
            process_zone.v0, process_zone.xi, bulk.material, bulk.n, bulk.k, bulk.l0)
        # as Python lists for the integrator's one-g-at-a-time calls (_speed_scalar; the
        # array path took 37-55 ms of a scene's 55 on the bench scenes, the PB law's 14-40)
        self._xs = self._spline.x.tolist()
        self._cs = self._spline.c.T.tolist()
        self._dcs = self._dspline.c.T.tolist()

    def process_zone_factor(self, v):
        """``Gamma_pz(v) / dg``."""
        return self.process_zone.gamma(v)

    def bulk_factor(self, v):
        """The bulk's Persson-Brener factor ``Gamma_PB(v / l0)``."""
        return self.bulk.gamma(np.maximum(np.asarray(v, dtype=float), 0.0))

    def gamma(self, v):
        return (np.asarray(self.process_zone_factor(v)) * self.bulk_factor(v))[()]

    def speed(self, g):
        """``V(g)`` and ``dV/dg`` (0 where ``g <= 1``)."""
        if isinstance(g, float):          # a Python or numpy scalar: the integrator's call
            return self._speed_scalar(float(g))
        x = np.asarray(g, dtype=float) - 1.0
        v, dv = np.zeros(x.shape), np.zeros(x.shape)
        pos = x > 0
        if pos.any():
            (x_lo, y_lo, s_lo), (x_hi, y_hi, s_hi) = self._ends
            lx = np.log(x[pos])
            y = np.where(lx < x_lo, y_lo + s_lo * (lx - x_lo),
                         np.where(lx > x_hi, y_hi + s_hi * (lx - x_hi),
                                  self._spline(np.clip(lx, x_lo, x_hi))))
            dy = np.where(lx < x_lo, s_lo, np.where(lx > x_hi, s_hi,
                                                   self._dspline(np.clip(lx, x_lo, x_hi))))
            v[pos] = np.exp(y)
            dv[pos] = v[pos] * dy / x[pos]
        return v[()], dv[()]

    def _speed_scalar(self, g):
        """:meth:`speed` of one ``g`` in Python floats: the table's ends extended linearly in
        (ln(g - 1), ln v), between them the spline's piece evaluated term by term
        (:meth:`PerssonBrenerLaw._speed_scalar`)."""
        x = g - 1.0
        if not x > 0.0:
            return 0.0, 0.0
        (x_lo, y_lo, s_lo), (x_hi, y_hi, s_hi) = self._ends
        lx = math.log(x)
        if lx < x_lo:
            y, dy = y_lo + s_lo * (lx - x_lo), s_lo
        elif lx > x_hi:
            y, dy = y_hi + s_hi * (lx - x_hi), s_hi
        else:
            xs = self._xs
            i = min(max(bisect_right(xs, lx) - 1, 0), len(xs) - 2)
            s = lx - xs[i]
            s2 = s * s
            c0, c1, c2, c3 = self._cs[i]
            y = c3 + c2 * s + c1 * s2 + c0 * (s2 * s)
            d0, d1, d2 = self._dcs[i]
            dy = d2 + d1 * s + d0 * s2
        v = math.exp(y)
        return v, v * dy / x

    def __repr__(self):
        return f"ProcessZoneLaw({self.process_zone!r}, {self.bulk!r})"


@lru_cache(maxsize=32)
def _product_table(v0, xi, material, n, k, l0):
    """PCHIP of ``ln v`` against ``ln(Gamma - 1)`` for :class:`ProcessZoneLaw`, its
    derivative, and the ends ``(x, y, slope)`` of the table at both sides."""
    from scipy.interpolate import PchipInterpolator  # lazy: not on a BEM scene's path
    bulk = PerssonBrenerLaw(n, k, l0, material)
    v_pb, g_pb, q = bulk.table()
    lo = math.log10(v0) - min(10.0 / xi, PZ_TABLE_MAX_DECADES)
    hi = math.log10(v0) + min(8.0 / xi, PZ_TABLE_MAX_DECADES)
    lo_pb, hi_pb = math.log10(v_pb[0]), math.log10(v_pb[-1])
    below = np.logspace(lo, lo_pb, max(int((lo_pb - lo) * PZ_TABLE_PER_DECADE), 1) + 1)[:-1] \
        if lo < lo_pb else np.empty(0)
    above = np.logspace(hi_pb, hi, max(int((hi - hi_pb) * PZ_TABLE_PER_DECADE), 1) + 1)[1:] \
        if hi > hi_pb else np.empty(0)
    v = np.concatenate([below, v_pb, above])
    gb = np.concatenate([1.0 + q * below, g_pb, np.full(above.shape, g_pb[-1])])
    with np.errstate(over="ignore"):
        g = (1.0 + (v / v0) ** xi) * gb
        x, y = np.log(g - 1.0), np.log(v)
    far = ~np.isfinite(x)
    if far.any():    # (v/v0)^xi beyond floats (pz_v0 1e-30, xi 10): ln(Gamma - 1) in logs
        with np.errstate(divide="ignore"):
            x[far] = np.logaddexp(np.log(gb[far] - 1.0),
                                  np.log(gb[far]) + xi * np.log(v[far] / v0))
    ok = np.concatenate([[True], np.diff(x) > 1e-12])     # strictly increasing abscissa
    x, y = x[ok], y[ok]
    spline = PchipInterpolator(x, y)
    ends = ((x[0], y[0], (y[1] - y[0]) / (x[1] - x[0])),
            (x[-1], y[-1], (y[-1] - y[-2]) / (x[-1] - x[-2])))
    return spline, spline.derivative(), ends


def pb_law_for_scene(n, k, mu, material="mpl") -> PerssonBrenerLaw:
    """The PB law of a dimensionless scene: speeds in ``a_ref/tau0``, ``l0 = l0_hat(mu)``."""
    return PerssonBrenerLaw(n, k, units.l0_hat(mu), material)


def scene_law(n, k, mu, material="mpl", pz_law="none", pz_v0=None, pz_xi=None):
    """``Gamma(v)`` of the crack-front model for a dimensionless scene (speeds in a_ref/tau0):
    the bulk's Persson-Brener law (:func:`pb_law_for_scene`, k < 1) without a process zone;
    with the Gent-Schultz one (``pz_v0`` in a_ref/tau0, ``pz_xi``) the product
    :class:`ProcessZoneLaw`, or :class:`GentSchultzLaw` alone for an elastic bulk (k = 1).
    (:func:`simulate_crack` treats a nearly elastic bulk, 1/k - 1 <= :data:`NEARLY_ELASTIC`,
    with a constant bulk factor instead.)"""
    pz_law = check_choice("pz_law", pz_law, ("none", "gent-schultz"))
    if pz_law == "none":
        return pb_law_for_scene(n, k, mu, material)
    process_zone = GentSchultzLaw(pz_v0, pz_xi)
    if k == 1.0:
        return process_zone
    return ProcessZoneLaw(process_zone, pb_law_for_scene(n, k, mu, material))


# ============================================================================ unloading

@dataclass
class CrackFrontSolution:
    """One crack-front unloading (units of the module docstring).

    Attributes
    ----------
    status : {"ok", "failed"}
    reason : str
    pull_off : float
        Largest tensile load ``|min P|`` (pi dg R).
    a_pulloff, delta_pulloff, t_pulloff : float
        State at pull-off (a_ref, d_ref, tau0 since the start of unloading).
    crack_speed : float
        ``v = -da/dt`` at pull-off (a_ref/tau0), where ``dP/dt = 0`` gives it from the state:
        ``a |d delta/dt| / (a^2 - delta)``.
    gamma_pulloff : float
        ``Gamma / dg`` at pull-off (equals ``g`` there).
    a0, delta0 : float
        Initial (relaxed JKR) state.
    capped : bool
        The PB speed hit the end of its table (``Gamma`` within the table's last step of 1/k).
    steps, nfev, nlu : int
        Integrator statistics (accepted steps, right-hand-side and LU evaluations).
    trajectory : dict of ndarray
        ``t, delta, P, a, v, g`` at the accepted steps (pinned phase included).
    """

    status: str = "failed"
    reason: str = ""
    pull_off: float = math.nan
    a_pulloff: float = math.nan
    delta_pulloff: float = math.nan
    t_pulloff: float = math.nan
    crack_speed: float = math.nan
    gamma_pulloff: float = math.nan
    a0: float = math.nan
    delta0: float = math.nan
    capped: bool = False
    steps: int = 0
    nfev: int = 0
    nlu: int = 0
    trajectory: dict = field(default_factory=dict)

    @property
    def ok(self) -> bool:
        return self.status == "ok"


def initial_state(a0=None, delta0=None):
    """Relaxed JKR initial state ``(a0, delta0)`` from one of them (g = 1)."""
    if (a0 is None) == (delta0 is None):
        raise InputError("a0/delta0: give exactly one of a0 (initial contact radius) "
                         "and delta0 (initial indentation)")
    if a0 is not None:
        a0 = check_range("a0", a0, lo=FIXED_GRIP_A_MIN)
        return a0, float(jkr_indentation(a0))
    delta0 = check_range("delta0", delta0, lo=FIXED_GRIP_DELTA_MIN)
    return float(jkr_contact_radius(indentation=delta0)), delta0


class _OverBudget(RuntimeError):
    """The integration of :func:`unload` ran over its wall-time budget."""


def _finite(a):
    """asarray_chkfinite's check (its message), which scipy.linalg's LU makes on every call
    (a one-entry array, Radau's here, checked as its Python number)."""
    if not (cmath.isfinite(a.item()) if a.size == 1 else np.isfinite(a).all()):
        raise ValueError("array must not contain infs or NaNs")


def _lapack_lu(A):
    """Radau's LU factorization (real, or complex for its complex pair): LAPACK's getrf, as
    ``scipy.linalg.lu_factor(A, overwrite_a=True)`` calls it, without that function's
    per-call checks and batch dispatch (the ODE is one equation: its 1 x 1 systems cost less
    than the checks). The same numbers: the crack-front pull-offs of 200 PDMS-like scenes equal
    to the last bit, a quarter less time a scene (:func:`unload`)."""
    _finite(A)
    lu, piv, _ = (zgetrf if np.iscomplexobj(A) else dgetrf)(A, overwrite_a=True)
    return lu, piv


def _lapack_solve(factors, b):
    """Radau's solve with :func:`_lapack_lu`'s factors: LAPACK's getrs, as
    ``scipy.linalg.lu_solve(factors, b, overwrite_b=True)`` calls it."""
    lu, piv = factors
    _finite(b)
    complex_ = np.iscomplexobj(lu) or np.iscomplexobj(b)      # lu_solve's choice of routine
    x, _ = (zgetrs if complex_ else dgetrs)(lu, piv, b, overwrite_b=True)
    return x


def unload(law, *, rate, mu, a0=None, delta0=None, stop="pulloff", rtol=1e-8,
           a_end=0.02, time_budget_s=0.0) -> CrackFrontSolution:
    r"""Unload a relaxed JKR contact at constant speed with the crack-front model.

    Parameters
    ----------
    law : GentSchultzLaw or PerssonBrenerLaw
        ``Gamma(v)`` with ``v`` in a_ref/tau0 (any object with ``gamma``, ``speed``,
        ``g_threshold``).
    rate : float
        The paper's r-hat ``r tau0 / h0`` (> 0); ``d delta/dt = -rate * h0_hat(mu)``.
    mu : float
        Tabor parameter (> 0), only for ``h0_hat``: the crack-front model has no LJ law.
    a0, delta0 : float
        Initial JKR contact radius (>= 1/2, the fixed-grip stability limit) or indentation
        (>= -3/4); give exactly one.
    stop : {"pulloff", "separation"}
        Stop at the load minimum, or follow the contact until ``a < a_end * a0``.
    rtol : float
        Relative tolerance of the Radau integrator (absolute tolerance ``rtol * a0`` on a).
    a_end : float
        Fraction of ``a0`` at which a "separation" run stops, in (0, 1).
    time_budget_s : float
        Wall-time budget of the integration, s (0: none); a run over it is ``failed``.

    Returns
    -------
    CrackFrontSolution
        ``failed`` (with a reason) if the integrator fails, accepts a state below
        ``Gamma(0)`` beyond its tolerance (it stepped over the crack's motion: module
        docstring), or no load minimum is reached.
    """
    rate = check_positive("rate", rate)
    mu = check_positive("mu", mu)
    stop = check_choice("stop", stop, ("pulloff", "separation"))
    rtol = check_range("rtol", rtol, 1e-13, 1e-3)
    a_end = check_range("a_end", a_end, 0.0, 1.0, lo_open=True, hi_open=True)
    a0, delta0 = initial_state(a0, delta0)
    sol = CrackFrontSolution(a0=a0, delta0=delta0)
    ddot = -rate * units.h0_hat(mu)                   # d delta / dt (d_ref per tau0)
    g_th = float(law.g_threshold)
    # pinned phase: the edge stays at a0 until g(a0, delta) reaches Gamma(0)
    d1 = a0 * a0 - math.sqrt(2.0 * a0 * g_th) if g_th > 1.0 else delta0
    t1 = (d1 - delta0) / ddot

    from scipy.integrate import Radau      # lazy: not on a BEM scene's path
    from scipy.optimize import brentq     # lazy: as Radau

    def delta_of(t):
        return delta0 + ddot * t

    deadline = budget.deadline(time_budget_s)     # the scene's, where one is running

    def signed_speed(g):
        # V(g) continued oddly below the threshold: -V(2 g_th - g), dV/dg = V'(2 g_th - g)
        # (docstring: the exact solution never goes there; an overshoot is pulled back)
        if g >= g_th:
            return law.speed(g)
        v, dv = law.speed(2.0 * g_th - g)
        return -v, dv

    def rhs(t, y):
        if time.perf_counter() > deadline:
            raise _OverBudget(f"time budget: {budget.budget_seconds(time_budget_s):g} s spent "
                              f"in the integrator at a = {y[0]:.4g} (numerics time_budget_s)")
        a = max(y[0], 1e-300)
        g = (a * a - delta_of(t)) ** 2 / (2.0 * a)
        v, _ = signed_speed(g)
        return [-float(v)]

    def jac(t, y):
        a = max(y[0], 1e-300)
        d = delta_of(t)
        g = (a * a - d) ** 2 / (2.0 * a)
        _, dv = signed_speed(g)
        dg = (a * a - d) * (3.0 * a * a + d) / (2.0 * a * a)
        return [[-float(dv) * dg]]

    # time scale: the indentation at which a JKR contact with Gamma = g_max would be gone
    # (delta = a0^2 - sqrt(2 a0 g_max): a frozen contact opens only when g nears g_max = 1/k)
    g_max = float(getattr(law, "g_max", 1.0))
    span = (abs(delta0) + 2.0 * a0 * a0 + 10.0 + math.sqrt(2.0 * a0 * g_max)) / abs(ddot)
    atol = rtol * a0
    a_stop = a_end * a0
    ts, avals = [t1], [a0]              # the accepted states (the pinned start prepended below)
    # the loads at the last two accepted states and the dense output of the last step: a
    # tensile load minimum is bracketed by three states whose middle load is the smallest
    p_prev2, p_prev = math.inf, float(crack_front_load(a0, delta_of(t1)))
    dense_prev = None
    pulloff = None                      # (t, a) of the first tensile load minimum
    runaway = None                      # past the pull-off, where the edge ran away
    try:
        solver = Radau(rhs, t1, [a0], t1 + span, rtol=rtol, atol=atol, jac=jac,
                       first_step=min(1e-6 * span, 1e-3 / max(rate, 1.0)))
        solver.lu, solver.solve_lu = _lapack_lu, _lapack_solve
        while True:
            message = solver.step()
            if solver.status == "failed" and pulloff is not None:
                # following to separation past the pull-off: the edge runs away (g beyond
                # what any crack speed balances), the contact separates at once
                runaway = float(solver.y[0])
                break
            if solver.status == "failed":
                sol.reason = f"integrator: {message}"
                break
            t_old, t_new, a_new = solver.t_old, solver.t, float(solver.y[0])
            dense = solver.dense_output()
            d_new = delta_of(t_new)
            crossed = _crossed_threshold(a_new, d_new, g_th, atol + rtol * abs(a_new))
            if crossed:
                ts.append(t_new)
                avals.append(a_new)
                sol.reason = (f"integrator stepped across the crack's motion at t = {t_new:.6g} "
                              f"tau0: g = {crossed:.10g} below Gamma(0)/dg = {g_th:.10g} "
                              f"(a = {a_new:.6g}), which the crack-front equation never "
                              f"reaches once the edge moves (rtol {rtol:g})")
                break
            t_end = None
            if a_new <= a_stop:                          # the contact has nearly vanished
                t_end = brentq(lambda s: float(dense(s)[0]) - a_stop, t_old, t_new,
                               xtol=4.0 * np.finfo(float).eps * max(abs(t_new), 1.0))
            p_new = float(crack_front_load(a_new, d_new))
            if pulloff is None and p_prev < 0.0 and p_prev <= p_prev2 and p_new > p_prev:
                pieces = [(dense, t_old, t_new)]
                if dense_prev is not None:
                    pieces.insert(0, (dense_prev, dense_prev.t_old, t_old))
                pulloff = _load_minimum(pieces, delta_of)
                if t_end is not None and pulloff[0] > t_end:
                    pulloff = None                       # the minimum is beyond the stop
                elif stop == "pulloff":
                    while ts[-1] >= pulloff[0] and len(ts) > 1:
                        ts.pop()
                        avals.pop()
                    ts.append(pulloff[0])
                    avals.append(pulloff[1])
                    break
            if t_end is not None:
                ts.append(t_end)
                avals.append(float(dense(t_end)[0]))
                break
            ts.append(t_new)
            avals.append(a_new)
            if solver.status == "finished":
                break
            p_prev2, p_prev, dense_prev = p_prev, p_new, dense
    except _OverBudget as exc:
        sol.reason = str(exc)
        return sol
    except NUMERICAL_ERRORS as exc:   # reported; a bug (TypeError, ...) raises
        if is_internal_error(exc):
            raise
        sol.reason = f"integrator: {type(exc).__name__}: {exc}"
        return sol
    sol.steps, sol.nfev, sol.nlu = len(ts), int(solver.nfev), int(solver.nlu)
    t = np.asarray(([0.0] if t1 > 0 else []) + ts)
    a = np.asarray(([a0] if t1 > 0 else []) + avals)
    d = delta_of(t)
    g = energy_release_rate(a, d)
    v = np.asarray(law.speed(g)[0], dtype=float)
    sol.trajectory = {"t": t, "delta": d, "P": crack_front_load(a, d), "a": a, "v": v, "g": g}
    if sol.reason:
        return sol
    if pulloff is None:
        sol.reason = "no load minimum before the contact vanished or the time span ended"
        return sol
    tp, ap = pulloff
    dp = delta_of(tp)
    gp = float(energy_release_rate(ap, dp))
    sol.pull_off = -float(crack_front_load(ap, dp))
    sol.a_pulloff, sol.delta_pulloff, sol.t_pulloff = ap, dp, tp
    # the crack speed that makes dP/dt = 2 v (a^2 - delta) + 2 a d(delta)/dt vanish: the
    # edge's speed at a load minimum, from the state alone (V(g) there is as uncertain as g)
    sol.crack_speed, sol.gamma_pulloff = -ap * ddot / (ap * ap - dp), gp
    sol.capped = bool(getattr(law, "v_cap", math.inf) <= float(law.speed(gp)[0]) * (1.0 + 1e-12))
    sol.status = "ok"
    notes = []
    if sol.capped:
        notes.append("crack speed at the end of the Persson-Brener table (Gamma ~ 1/k)")
    if runaway is not None:
        g_end = float(energy_release_rate(a[-1], d[-1]))
        bound = f" against the law's largest Gamma/dg, {g_max:.6g}" if hasattr(law, "g_max") \
            else ""
        notes.append(f"followed to a = {runaway:.4g}, where the integrator finds no step (g = "
                     f"{g_end:.6g}{bound}): the edge runs away and the contact separates at "
                     f"once")
    sol.reason = "; ".join(notes)
    return sol


def _crossed_threshold(a, delta, g_th, tol):
    """``g(a, delta)`` if it lies below the threshold ``g_th`` by more than
    :data:`THRESHOLD_CROSSING` times the step's tolerance ``tol`` on ``a`` (carried to ``g``
    by ``max(|dg/da|, 1)``), else 0.0: a state the crack-front equation never reaches once
    the edge has depinned (:func:`unload`)."""
    g = (a * a - delta) ** 2 / (2.0 * a)
    dg = abs((a * a - delta) * (3.0 * a * a + delta)) / (2.0 * a * a)
    return g if g_th - g > THRESHOLD_CROSSING * max(dg, 1.0) * tol else 0.0


def _load_minimum(pieces, delta_of):
    """``(t, a)`` of the smallest load ``P(a(t), delta(t))`` over the integrator's dense output,
    ``pieces`` of ``(dense, t_from, t_to)`` (the steps around the bracketed minimum): a
    bounded Brent search in each, then the smallest of those and the pieces' ends."""
    from scipy.optimize import minimize_scalar  # lazy: not on a BEM scene's path

    best = (math.inf, math.nan, math.nan)
    for dense, lo, hi in pieces:
        def load(s, dense=dense):
            return float(crack_front_load(float(dense(s)[0]), delta_of(s)))

        res = minimize_scalar(load, bounds=(lo, hi), method="bounded",
                              options={"xatol": 1e-10 * max(hi - lo, 1e-300)})
        for s in (lo, float(res.x), hi):
            best = min(best, (load(s), s, float(dense(s)[0])))
    return best[1], best[2]


def answers(scene) -> bool:
    """Whether the crack-front model runs ``scene``: a relaxed start (no test protocol) on a
    rigid machine (no ``machine_stiffness``) from a contact that is stable under fixed grip
    (``a0`` at least :data:`FIXED_GRIP_A_MIN`, or a start given by ``delta0``). A failure's
    advice names the model only where it does (:mod:`sweep.engine.models` refuses the rest,
    each with its reason)."""
    return (scene.protocol() is None and scene.machine_stiffness is None
            and (scene.a0 is None or scene.a0 >= FIXED_GRIP_A_MIN))


def crack_front_advice(scene) -> str:
    """", or use the crack-front model (model crack)" where that model runs ``scene``
    (:func:`answers`), else "": the end of a BEM failure's advice."""
    return ", or use the crack-front model (model crack)" if answers(scene) else ""


#: a scene whose Gamma(v)/dg - 1 at RELAXED_SPEEDS times its loading speed (a bound of the
#: crack speed at the pull-off: 2.3 times it for JKR at Gamma = dg) is at most RELAXED_LIMIT is
#: the relaxed limit, the JKR contact at Gamma = dg (:func:`simulate_crack`): below a rate of
#: about 1e-11 (n 0.8, k 0.1, mu 3.24), where the integrator's g - 1 drowned in the rounding of
#: g (the edge pinned for good below rate 1e-29, the time budget spent; 1.4999998 at 1e-28)
RELAXED_SPEEDS = 10.0
RELAXED_LIMIT = 1e-10


def simulate_crack(scene, numerics=None):
    """Run a :class:`sweep.Scene` with the crack-front model and its law :func:`scene_law`:
    the material's PB law, times the Gent-Schultz process zone where the scene has one (a
    nearly elastic bulk, 1/k - 1 <= :data:`NEARLY_ELASTIC`, contributes the constant factor
    ``c = 1/sqrt(k)``, its ``error_estimate`` ``c - 1``; 0 at k = 1; there a process zone
    below :data:`NEGLIGIBLE_PROCESS_ZONE` is none).

    Returns a :class:`sweep.Result` (the BEM's row format): ``pull_off``, ``a_pulloff``,
    ``delta_pulloff``, ``t_pulloff``, ``crack_speed``, ``vhat``, ``rhat_pb``, ``a0_result``,
    ``delta0_result``, ``steps`` (accepted steps), ``newton_iterations`` (right-hand-side
    evaluations), ``factorizations`` (LU); mesh and LJ fields (``a_inner*``, ``spacing``,
    ``domain_used``, ``prony_*``) are NaN/0: the model has none. A scene given by ``a0`` starts
    at the JKR state of that radius (the BEM's ``a0`` is the LJ max-tension radius, which tends
    to it as mu grows).
    """
    numerics = Numerics.preset("balanced") if numerics is None else numerics
    t_start = time.perf_counter()
    res = Result(scene=scene, numerics=numerics)
    if scene.a0 is not None and scene.a0 < FIXED_GRIP_A_MIN:
        res.reason = (f"no stable contact of radius a0 = {scene.a0:g}: below "
                      f"{FIXED_GRIP_A_MIN:g} a_ref a JKR contact is not stable under fixed grip "
                      f"(the crack-front model, the mu -> infinity limit, starts at or above it)")
        return res
    if scene.delta0 is not None and scene.delta0 < FIXED_GRIP_DELTA_MIN:
        res.reason = (f"no stable contact at delta0 = {scene.delta0:g}: below "
                      f"{FIXED_GRIP_DELTA_MIN:g}, "
                      f"the indentation of the JKR contact of radius {FIXED_GRIP_A_MIN:g} a_ref, "
                      f"the smallest stable under fixed grip (the crack-front model, the mu -> "
                      f"infinity limit)")
        return res
    if scene.pz_law != "none" and scene.pz_xi < PZ_XI_MIN:
        res.reason = (f"pz_xi = {scene.pz_xi:g} is below {PZ_XI_MIN:g}, the smallest exponent "
                      f"the crack-front model follows: the process zone's term (v/pz_v0)^pz_xi "
                      f"is then a step of Gamma at v = 0+, whose inverse V(g) overflows")
        return res
    nearly_elastic = 1.0 / scene.k - 1.0 <= NEARLY_ELASTIC * (1.0 + 1e-12)
    if nearly_elastic:
        closed = _elastic_crack(scene, Result(scene=scene, numerics=numerics), t_start)
        if scene.pz_law == "none":
            return closed
        # a process zone too weak to count, at the constant-Gamma contact's crack speed
        term = negligible_zone_term(scene, closed.crack_speed)
        if term <= NEGLIGIBLE_PROCESS_ZONE:
            closed.error_estimate += term
            return closed
    try:
        if nearly_elastic:         # the bulk a constant factor c = 1/sqrt(k), as _elastic_crack
            c = 1.0 / math.sqrt(scene.k)
            law = GentSchultzLaw(scene.pz_v0, scene.pz_xi, c=c)
            res.error_estimate = c - 1.0
        else:
            law = scene_law(scene.n, scene.k, scene.mu, scene.material, scene.pz_law,
                            scene.pz_v0, scene.pz_xi)
            slow = float(law.gamma(RELAXED_SPEEDS * scene.rate * units.h0_hat(scene.mu))) - 1.0
            if slow <= RELAXED_LIMIT:
                closed = _elastic_crack(scene, Result(scene=scene, numerics=numerics), t_start,
                                        c=1.0)
                closed.error_estimate = max(slow, 0.0)
                note = (f"the relaxed limit: Gamma(v)/dg - 1 = {slow:.2g} at {RELAXED_SPEEDS:g} "
                        f"times the loading speed (at most {RELAXED_LIMIT:g}): the JKR contact "
                        f"at the constant Gamma = dg")
                closed.reason = f"{note}; {closed.reason}" if closed.reason else note
                return closed
        s = unload(law, rate=scene.rate, mu=scene.mu, a0=scene.a0, delta0=scene.delta0,
                   stop=scene.stop, time_budget_s=numerics.time_budget_s)
    except NUMERICAL_ERRORS as exc:   # reported; a bug (TypeError, ...) raises
        if is_internal_error(exc):
            raise
        res.reason = f"{type(exc).__name__}: {exc}"
        res.wall_s = time.perf_counter() - t_start
        return res
    res.status, res.reason = s.status, s.reason
    res.pull_off, res.a_pulloff = s.pull_off, s.a_pulloff
    res.delta_pulloff, res.t_pulloff = s.delta_pulloff, s.t_pulloff
    res.crack_speed = s.crack_speed
    res.vhat = float(units.vhat_from_crack_speed(s.crack_speed, scene.mu))
    res.rhat_pb = float(units.rhat_pb(scene.rate, scene.mu))
    res.a0_result, res.delta0_result = s.a0, s.delta0
    res.steps, res.newton_iterations, res.factorizations = s.steps, s.nfev, s.nlu
    res.prony_terms, res.prony_error = 0, 0.0
    tr = s.trajectory
    if tr:
        res.trajectory = {"t": tr["t"], "delta": tr["delta"], "P": tr["P"], "a": tr["a"],
                          "a_inner": np.full(tr["a"].shape, np.nan)}
    res.wall_s = time.perf_counter() - t_start
    return res


def _elastic_crack(scene, res, t_start, c=None):
    """A (nearly) elastic scene, 1/k - 1 <= :data:`NEARLY_ELASTIC`, with the crack-front
    model: the JKR contact opened at the constant Gamma = c dg, c = 1/sqrt(k) (or ``c``
    given: 1, the relaxed limit of a scene too slow for its Gamma(v) to rise above dg), under
    fixed grip (:func:`constant_gamma_pull_off`); the crack speed at the pull-off radius follows
    from the indentation speed, v = rate h0 / (d delta/d a) (none where a0 is below the
    load-control pull-off radius: there the tension is largest at the start)."""
    c = 1.0 / math.sqrt(scene.k) if c is None else c
    a0 = scene.a0 if scene.a0 is not None else float(jkr_contact_radius(indentation=scene.delta0))
    a_load = A_PULL_OFF_FORCE * c ** (1.0 / 3.0)        # the load-control pull-off radius
    a_po = a_load if a0 >= a_load else a0
    res.status, res.pull_off = "ok", constant_gamma_pull_off(a0, c)
    res.a0_result, res.delta0_result = a0, float(jkr_indentation(a0))
    res.a_pulloff = a_po
    res.delta_pulloff = a_po * a_po - math.sqrt(2.0 * c * a_po)    # g(a, delta) = c
    speed = scene.rate * units.h0_hat(scene.mu)
    res.t_pulloff = max(res.delta0_result - res.delta_pulloff, 0.0) / speed
    slope = 2.0 * a_po - math.sqrt(c / (2.0 * a_po))                # d delta / d a at g = c
    res.crack_speed = speed / slope if a0 >= a_load else math.nan
    res.vhat = float(units.vhat_from_crack_speed(res.crack_speed, scene.mu))
    res.rhat_pb = float(units.rhat_pb(scene.rate, scene.mu))
    res.prony_terms, res.prony_error = 0, 0.0
    res.error_estimate = c - 1.0            # Gamma(v) within [dg, dg/k]: |c k^(-1/2) - 1|
    if scene.stop == "separation":
        res.trajectory = _elastic_separation(a0, res.delta0_result, c, speed)
        res.reason = (f"followed under fixed grip to its instability, a = "
                      f"{res.trajectory['a'][-1]:.4g} (d delta/d a = 0 at g = {c:.4g}), where "
                      f"the contact separates at once")
    res.wall_s = time.perf_counter() - t_start
    return res


#: points of a nearly elastic contact's path to separation (:func:`_elastic_separation`)
SEPARATION_POINTS = 200


def _elastic_separation(a0, delta0, c, speed) -> dict:
    """The path of a JKR contact opened at the constant Gamma = c dg under fixed grip, from
    the relaxed contact of radius ``a0`` at ``delta0`` (its edge pinned until g reaches c) to
    the fixed-grip instability, d delta/d a = 0 at a = (c/32)^(1/5) (1/2 and P = -5/6 at c =
    1), where it separates: records ``t, delta, P, a, a_inner`` (``a_inner`` NaN) at the
    indentation ``speed`` (d_ref/tau0)."""
    a_end = (c / 32.0) ** 0.2
    a = np.linspace(a0, a_end, SEPARATION_POINTS) if a0 > a_end else np.array([a0])
    delta = a * a - np.sqrt(2.0 * c * a)
    a, delta = np.append(a0, a), np.append(delta0, delta)        # the pinned start
    t = (delta0 - delta) / speed
    return {"t": t, "delta": delta, "P": crack_front_load(a, delta), "a": a,
            "a_inner": np.full(a.size, np.nan)}
