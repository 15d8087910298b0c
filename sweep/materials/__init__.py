"""Linear viscoelastic materials: creep, relaxation, complex moduli and Prony fits.

Conventions (docs/design.md section 3; binding for every material here)
------------------------------------------------------------------------
* ``E0`` is the RELAXED (long-time, rubbery) modulus and ``Einf`` the GLASSY (instantaneous)
  modulus, ``Einf >= E0 > 0``; ``k = E0 / Einf`` in (0, 1].  ``C0 = 1/E0`` and
  ``Cinf = 1/Einf`` are the relaxed and glassy compliances.  (Beware: some libraries call the
  glassy modulus ``E_0``; here it is always the relaxed one, as in the paper.)
* ``tau0`` is the characteristic time; physical times ``t`` and angular frequencies ``omega``
  are in the units of ``tau0`` and ``1/tau0`` (e.g. s and rad/s).  Moduli carry the units of
  ``E0`` and compliances their inverse.
* Normalized time ``that = t / tau0``.  The normalized creep compliance is
  ``Chat(that) = C(t) / C0``: ``Chat(0) = k`` and ``Chat(inf) = 1``, non-decreasing.  The
  normalized relaxation modulus is ``Rhat(that) = R(t) / E0``: ``Rhat(0) = 1/k``,
  ``Rhat(inf) = 1``.
* Integrated compliance ``Psi(T) = int_0^T Chat(s) ds`` (``T`` in units of tau0), used by the
  exact-convolution reference solver (docs/design.md section 4).
* Frequency domain (paper, appendix A): complex modulus ``E(omega) = E' + i E''`` and complex
  compliance ``C(omega) = C' - i C'' = 1 / E(omega)``, with ``E'' >= 0`` and ``C'' >= 0``
  (harmonic time factor ``exp(i omega t)``).

Models
------
``MPLRetardation``
    modified power law RETARDATION spectrum (paper eq. retspec; the model of the BEM, of the
    Persson-Brener theory; docs/design.md section 3): the retardation times, in units of tau0, are
    Gamma(n, 1) distributed, ``Chat(t) = 1 - (1-k) 2 t^(n/2) K_n(2 sqrt t) / Gamma(n)``.
    Creep and complex compliance in closed form; relaxation modulus numerical.
``MPLRelaxation``
    modified power law RELAXATION spectrum (paper eq. relspec), a DIFFERENT material with the
    same four constants: the relaxation rates, in units of 1/tau0, are Gamma(n, 1) distributed,
    ``R(t) = E0 + (Einf - E0) / (1 + t/tau0)^n``.  Relaxation and complex modulus in closed
    form; creep compliance numerical.
``SLS``
    standard linear solid in Kelvin form with RETARDATION time tau0,
    ``Chat(t) = 1 - (1-k) exp(-t/tau0)`` (its relaxation time is ``k tau0``).  All closed form.
``Prony``
    a generic table: Kelvin (retardation) ``Chat = 1 - sum c_i exp(-t/tau_i)`` or Wiechert /
    generalized Maxwell ``R = E0 + sum E_i exp(-t/tau_i)``; each is converted exactly into the
    other (partial fractions), so every method is closed form.

Every material has ``.prony(t_min, t_max, rtol)``, which returns the :class:`PronySeries` with
the fewest terms found that approximates ``Chat`` on ``[t_min, t_max]`` (units of tau0) within
the relative error ``rtol``; the series drives the O(N) hereditary recursion of docs/design.md
section 4.

"Numerical" above means: the Gamma-distributed spectrum is discretized by the trapezoidal rule
in log time (exponentially convergent, relative error ~1e-13), the far tail outside the times
requested is lumped into one mode with the same mass and mean time (second-order error), and
the resulting Maxwell/Kelvin table is converted exactly into the other form.  Accuracy about
1e-12 relative, measured in ``tests/test_materials.py`` (hereditary integral R * dC = 1 and
C(omega) E(omega) = 1 against the closed forms of the other side).

Validation: every invalid parameter raises :class:`sweep.errors.InputError` whose one-line
message names the parameter and the allowed range.

Modules (one concept each; import the public names from ``sweep.materials``)
----------------------------------------------------------------------------
``base``          the shared interface ``_Material`` (moduli, k, tau0, ``.prony``)
``mpl``           ``MPLRetardation``, ``MPLRelaxation``
``sls``           ``SLS``
``prony_table``   ``Prony`` (a Kelvin or Wiechert table as a material)
``prony_files``   ``read_prony``, ``PronyTable`` (a lab's Prony table file, several formats)
``prony_series``  ``PronySeries`` (the fitted series the solver uses)
``fitting``       the Prony fitter ``fit_prony``
``varpro``        its compiled Levenberg-Marquardt on the log times (Numba; NNLS inside)
``tables``        Kelvin/Maxwell tables: evaluation and exact conversion
``closed_forms``  MPL and SLS creep compliance and integrated compliance in closed form
``special``       the generalized exponential integral ``expint``, ``expint_scaled``
"""
from __future__ import annotations

from ._checks import MAX_WINDOW_DECADES, N_MAX
from .closed_forms import (mpl_integrated_compliance, mpl_normalized_creep_compliance,
                           sls_integrated_compliance)
from .fitting import CHECK_PPD, FIT_PPD, fit_prony
from .mpl import MPLRelaxation, MPLRetardation
from .prony_series import PronySeries
from .prony_files import PronyTable, read_prony
from .prony_table import Prony
from .sls import SLS
from .special import expint, expint_scaled
from .tables import kelvin_to_maxwell, maxwell_to_kelvin

__all__ = [
    "MPLRetardation",
    "MPLRelaxation",
    "SLS",
    "Prony",
    "PronyTable",
    "read_prony",
    "PronySeries",
    "expint",
    "expint_scaled",
    "mpl_normalized_creep_compliance",
    "mpl_integrated_compliance",
    "sls_integrated_compliance",
    "maxwell_to_kelvin",
    "kelvin_to_maxwell",
]
