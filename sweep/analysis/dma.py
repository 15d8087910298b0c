r"""DMA fitting: from a measured complex modulus to the four MPL constants (and a Prony table).

Input (CSV with a header line, SI units; extra columns are ignored):

* a master curve ``omega_rad_s, E_storage_Pa, E_loss_Pa`` (already at the reference
  temperature), or
* a temperature sweep ``T_C, f_Hz, E_storage_Pa, E_loss_Pa``, shifted to the reference
  temperature ``T_ref`` with the paper's WLF equation (aT), written about the glass
  transition temperature ``Tg``:

  .. math:: \log_{10} a_T(T) = \frac{-C_1 (T - T_g)}{C_2 + T - T_g},\qquad
            \omega_{red} = 2\pi f\;10^{\log_{10} a_T(T) - \log_{10} a_T(T_{ref})}

  (paper: C1 = 17.44, C2 = 51.6 K, Tg = -115 C, T_ref = 20 C; a colder point moves to a
  higher reduced frequency).

Fits (conventions of :mod:`sweep.materials`: ``E0`` RELAXED, ``Einf`` GLASSY modulus,
``E = E' + i E''``):

* :func:`fit_mpl` -- the MPL RETARDATION model (as the paper, eq. Comega, the model of the BEM):
  ``C(omega) = Cinf + (C0 - Cinf) E[1/(1 + i omega tau0 x)]``, ``x ~ Gamma(n)``, and
  ``E = 1/C``. Nonlinear least squares (scipy ``least_squares``, trust region) on the log
  residuals ``ln E'_model - ln E'_data`` and ``ln E''_model - ln E''_data`` over the
  parameters ``(ln E0, ln Einf, n, ln tau0)``, started from the best point of a coarse grid in
  ``(n, ln tau0)``. Standard errors from the Jacobian at the optimum,
  ``cov = s^2 (J^T J)^-1`` with ``s^2`` the residual variance per degree of freedom.
* :func:`fit_maxwell` -- a generalized Maxwell (Wiechert) model with ``N`` arms,
  ``E(omega) = E0 + sum_i E_i i omega tau_i / (1 + i omega tau_i)``; the relaxation times are
  log-spaced over the data's decades (``1/omega_max .. 1/omega_min``) and the moduli
  ``E0, E_i >= 0`` come from non-negative least squares (scipy ``nnls``) on the relative
  residuals of ``E'`` and ``E''``.
* :func:`kramers_kronig_check` -- a linear Kramers-Kronig test: a dense Wiechert model
  (always causal, hence KK-consistent) is fitted to ``E'`` ALONE and its ``E''`` is compared
  with the measured loss modulus, relative to ``|E*|``; above the stated tolerance (which
  grows with the data's stated noise) the data (or the shift) violate KK.

pyvisco (the DMA Prony-identification library) was considered for the Maxwell comparison and
not added: version 2.1.3 requires a notebook/GUI stack (jupyterlab, voila, ipywidgets, ipympl,
notebook) as hard dependencies.
"""
from __future__ import annotations

import csv
import math
import os
from dataclasses import dataclass, field

import numpy as np
from scipy.interpolate import PchipInterpolator
from scipy.optimize import least_squares, nnls

from ..errors import InputError, check_int, check_range
from ..materials import MPLRetardation, Prony

__all__ = [
    "WLF_PAPER", "DMAData", "MPLFit", "MaxwellFit", "KKCheck", "KK_FLOOR", "KK_NOISE_FACTOR",
    "wlf_log_shift", "read_dma_csv", "fit_mpl", "fit_maxwell", "kramers_kronig_check",
    "plot_dma",
]

#: The paper's WLF constants (eq. aT): C1, C2 [K], Tg [C].
WLF_PAPER = (17.44, 51.6, -115.0)

MASTER_COLUMNS = ("omega_rad_s", "E_storage_Pa", "E_loss_Pa")
SWEEP_COLUMNS = ("T_C", "f_Hz", "E_storage_Pa", "E_loss_Pa")
MIN_ROWS = 3


# ============================================================================ reading

def wlf_log_shift(T, C1=WLF_PAPER[0], C2=WLF_PAPER[1], Tg=WLF_PAPER[2]):
    r"""The paper's WLF shift, ``log10 a_T`` relative to ``Tg`` (eq. aT).

    .. math:: \log_{10} a_T = \frac{-C_1 (T - T_g)}{C_2 + T - T_g}

    Parameters
    ----------
    T : float or array_like
        Temperature [C], ``T > Tg - C2`` (the WLF pole).
    C1 : float
        Dimensionless constant (> 0).
    C2 : float
        Constant [K] (> 0).
    Tg : float
        Glass transition temperature [C].
    """
    T = np.asarray(T, dtype=float)
    if np.any(T - Tg <= -C2):
        bad = float(T[T - Tg <= -C2].ravel()[0])
        raise InputError(f"T_C must be > Tg - C2 = {Tg - C2:g} C for the WLF shift (got {bad:g})")
    return (-C1 * (T - Tg) / (C2 + T - Tg))[()]


@dataclass
class DMAData:
    """A master curve at the reference temperature.

    Attributes
    ----------
    omega : ndarray
        Angular frequency [rad/s], ascending.
    E_storage, E_loss : ndarray
        ``E'`` and ``E''`` [Pa].
    source : str
        File name (or a description).
    kind : {"master", "temperature"}
        What the file held.
    T_ref : float or None
        Reference temperature [C] of a shifted temperature sweep.
    wlf : tuple or None
        ``(C1, C2, Tg)`` used for the shift.
    T : ndarray or None
        The temperature of each point (temperature sweeps only), ordered like ``omega``.
    """

    omega: np.ndarray
    E_storage: np.ndarray
    E_loss: np.ndarray
    source: str = ""
    kind: str = "master"
    T_ref: float | None = None
    wlf: tuple | None = None
    T: np.ndarray | None = None

    @property
    def modulus(self) -> np.ndarray:
        """Complex modulus ``E' + i E''`` [Pa]."""
        return self.E_storage + 1j * self.E_loss


def _parse_cell(path, line_no, row_no, column, text, positive, nonneg=False):
    where = f"{path} line {line_no} (data row {row_no}), column {column}"
    try:
        x = float(text)
    except (TypeError, ValueError):
        raise InputError(f"{where}: must be a number (got {text!r})") from None
    if not math.isfinite(x):
        raise InputError(f"{where}: must be a finite number (got {text.strip()})")
    if positive and not x > 0.0:
        raise InputError(f"{where}: must be > 0 (got {x:g})")
    if nonneg and x < 0.0:
        raise InputError(f"{where}: must be >= 0 (got {x:g})")
    return x


def read_dma_csv(path, T_ref: float = 20.0, wlf=WLF_PAPER) -> DMAData:
    """Read a master curve or a temperature sweep (module docstring) into a :class:`DMAData`.

    Parameters
    ----------
    path : str or path-like
        CSV file with a header line; columns by name, any order, extra columns ignored.
    T_ref : float
        Reference temperature [C] for a temperature sweep (ignored for a master curve).
    wlf : (C1, C2, Tg)
        WLF constants (C1 > 0, C2 > 0 [K], Tg [C]) for a temperature sweep.

    Raises
    ------
    InputError
        One line naming the file, the line / data row and the column: missing columns,
        a cell that is not a finite number, a non-positive frequency or storage modulus,
        a non-positive loss modulus, fewer than 3 data rows.
    """
    path = os.fspath(path)
    C1 = check_range("wlf C1", wlf[0], lo=0.0, lo_open=True)
    C2 = check_range("wlf C2", wlf[1], lo=0.0, lo_open=True)
    Tg = check_range("wlf Tg", wlf[2], lo=-273.15)
    T_ref = check_range("tref", T_ref, lo=Tg - C2, lo_open=True)
    try:
        with open(path, newline="", encoding="utf-8-sig") as fh:     # a BOM (Excel) dropped
            rows = [r for r in csv.reader(fh)]
    except OSError as exc:
        raise InputError(f"{path}: cannot read the file ({exc.strerror})") from None
    lines = [(i + 1, r) for i, r in enumerate(rows) if r and any(c.strip() for c in r)]
    if not lines:
        raise InputError(f"{path}: empty file (expected a header with columns "
                         f"{', '.join(MASTER_COLUMNS)} or {', '.join(SWEEP_COLUMNS)})")
    header = [c.strip() for c in lines[0][1]]
    if all(c in header for c in MASTER_COLUMNS):
        kind, cols = "master", MASTER_COLUMNS
    elif all(c in header for c in SWEEP_COLUMNS):
        kind, cols = "temperature", SWEEP_COLUMNS
    else:
        want = MASTER_COLUMNS if "omega_rad_s" in header or "T_C" not in header else SWEEP_COLUMNS
        missing = [c for c in want if c not in header]
        raise InputError(f"{path} line {lines[0][0]}: missing column(s) {', '.join(missing)} "
                         f"(a master curve needs {', '.join(MASTER_COLUMNS)}; a temperature "
                         f"sweep needs {', '.join(SWEEP_COLUMNS)})")
    idx = {c: header.index(c) for c in cols}
    data = {c: [] for c in cols}
    for row_no, (line_no, r) in enumerate(lines[1:], start=1):
        for c in cols:
            text = r[idx[c]] if idx[c] < len(r) else ""
            if text.strip() == "":
                raise InputError(f"{path} line {line_no} (data row {row_no}), column {c}: "
                                 f"missing value")
            positive = c != "T_C"
            data[c].append(_parse_cell(path, line_no, row_no, c, text, positive))
    n_rows = len(data[cols[0]])
    if n_rows < MIN_ROWS:
        raise InputError(f"{path}: needs at least {MIN_ROWS} data rows for a 4-parameter fit "
                         f"(got {n_rows})")
    E1 = np.array(data["E_storage_Pa"])
    E2 = np.array(data["E_loss_Pa"])
    T = None
    if kind == "master":
        omega = np.array(data["omega_rad_s"])
    else:
        T = np.array(data["T_C"])
        bad = np.nonzero(T - Tg <= -C2)[0]
        if bad.size:
            line_no = lines[1 + bad[0]][0]
            raise InputError(f"{path} line {line_no} (data row {bad[0] + 1}), column T_C: must be "
                             f"> Tg - C2 = {Tg - C2:g} C for the WLF shift (got {T[bad[0]]:g})")
        shift = wlf_log_shift(T, C1, C2, Tg) - wlf_log_shift(T_ref, C1, C2, Tg)
        with np.errstate(over="ignore"):
            omega = 2.0 * math.pi * np.array(data["f_Hz"]) * 10.0 ** shift
        bad = np.nonzero(~np.isfinite(omega) | (omega <= 0.0))[0]
        if bad.size:           # a temperature just above the WLF pole: a shift of 10^500
            line_no = lines[1 + bad[0]][0]
            raise InputError(f"{path} line {line_no} (data row {bad[0] + 1}), column T_C: the "
                             f"WLF shift to {T_ref:g} C at {T[bad[0]]:g} C is 10^{shift[bad[0]]:.4g}, "
                             f"beyond the floats (T_C within a few degrees of Tg - C2 = "
                             f"{Tg - C2:g} C: check wlf)")
    distinct = np.unique(omega).size
    if distinct < MIN_ROWS:
        raise InputError(f"{path}: needs at least {MIN_ROWS} distinct frequencies for a "
                         f"4-parameter fit (got {distinct} among {n_rows} rows)")
    order = np.argsort(omega, kind="stable")
    return DMAData(omega=omega[order], E_storage=E1[order], E_loss=E2[order], source=path,
                   kind=kind, T_ref=T_ref if kind == "temperature" else None,
                   wlf=(C1, C2, Tg) if kind == "temperature" else None,
                   T=None if T is None else T[order])


def _as_data(data) -> DMAData:
    """A :class:`DMAData` as given, or one built from ``(omega, E', E'')`` arrays: checked
    (finite, > 0, equal lengths, at least 3 points) and sorted by frequency."""
    if isinstance(data, DMAData):
        return data
    omega, E1, E2 = (np.asarray(x, dtype=float).ravel() for x in data)
    if not omega.size == E1.size == E2.size:
        raise InputError(f"omega, E_storage and E_loss must have equal lengths "
                         f"(got {omega.size}, {E1.size}, {E2.size})")
    if omega.size < MIN_ROWS:
        raise InputError(f"omega must hold at least {MIN_ROWS} points (got {omega.size})")
    for name, x in (("omega", omega), ("E_storage", E1), ("E_loss", E2)):
        bad = ~(np.isfinite(x) & (x > 0))
        if bad.any():
            i = int(np.nonzero(bad)[0][0])
            raise InputError(f"{name}[{i}] must be a finite number > 0 (got {x[i]:g})")
    order = np.argsort(omega, kind="stable")
    return DMAData(omega[order], E1[order], E2[order], source="<arrays>")


def _quality(data: DMAData, E_model: np.ndarray) -> dict:
    """rms and max of the relative residuals of E' and E'' (model/data - 1)."""
    r1 = E_model.real / data.E_storage - 1.0
    r2 = E_model.imag / data.E_loss - 1.0
    return {
        "rms_rel_storage": float(np.sqrt(np.mean(r1**2))),
        "rms_rel_loss": float(np.sqrt(np.mean(r2**2))),
        "max_rel_storage": float(np.max(np.abs(r1))),
        "max_rel_loss": float(np.max(np.abs(r2))),
    }


# ============================================================================ MPL

@dataclass
class MPLFit:
    """Result of :func:`fit_mpl` (SI: moduli in Pa, tau0 in s).

    Attributes
    ----------
    E0, Einf, n, tau0 : float
        The four MPL constants (retardation form).
    stderr : dict
        One-sigma standard errors of the four constants (same units), from the Jacobian.
    rel_stderr : dict
        Standard errors relative to the values.
    quality : dict
        ``rms_rel_storage``, ``rms_rel_loss``, ``max_rel_*`` (relative residuals) and
        ``rms_log`` (rms of all log residuals, the objective), ``dof``.
    success : bool
        The optimizer's convergence flag.
    message : str
    at_bound : dict
        The constants that ended on a bound of the fit, each with which one (e.g.
        ``{"Einf": "upper bound 100 x max E'"}``): the data do not constrain them, so the
        value is the bound, not an estimate, and their ``stderr`` is NaN (no interval); the
        other constants' errors are those with these held fixed.
    """

    E0: float
    Einf: float
    n: float
    tau0: float
    stderr: dict
    rel_stderr: dict
    quality: dict
    success: bool
    message: str = ""
    at_bound: dict = field(default_factory=dict)

    @property
    def k(self) -> float:
        return self.E0 / self.Einf

    @property
    def material(self) -> MPLRetardation:
        """The fitted material (:class:`sweep.materials.MPLRetardation`)."""
        return MPLRetardation(self.E0, self.Einf, self.n, self.tau0)

    def to_dict(self) -> dict:
        return {"E0": self.E0, "Einf": self.Einf, "n": self.n, "tau0": self.tau0, "k": self.k,
                "stderr": {k: (None if not math.isfinite(v) else v)
                           for k, v in self.stderr.items()},
                "rel_stderr": {k: (None if not math.isfinite(v) else v)
                               for k, v in self.rel_stderr.items()},
                "quality": self.quality, "success": self.success, "message": self.message,
                "at_bound": dict(self.at_bound)}


_N_BOUNDS = (1e-3, 5.0)


def _mpl_modulus(p, omega):
    E0, Einf, n, tau0 = math.exp(p[0]), math.exp(p[1]), p[2], math.exp(p[3])
    if Einf < E0:           # outside the model: mirror (the optimizer is kept away by bounds)
        E0, Einf = Einf, E0
    return MPLRetardation(E0, Einf, n, tau0).complex_modulus(omega)


def _mpl_residuals(p, data):
    E = _mpl_modulus(p, data.omega)
    with np.errstate(divide="ignore", invalid="ignore"):
        r = np.concatenate([np.log(E.real / data.E_storage), np.log(E.imag / data.E_loss)])
    return np.where(np.isfinite(r), r, 50.0)


def fit_mpl(data) -> MPLFit:
    r"""Fit the MPL retardation model to a complex modulus (module docstring: method).

    Parameters
    ----------
    data : DMAData or (omega, E_storage, E_loss)
        Angular frequency [rad/s] and moduli [Pa], ``E' > 0``, ``E'' > 0``.

    Returns
    -------
    MPLFit
        Constants in SI with standard errors and fit quality. The relaxed modulus is bounded
        to ``[min E'/100, 2 min E']`` and the glassy one to ``[max E'/2, 100 max E']``; data
        that do not reach a plateau show it as a large standard error or, when the constant
        ends on its bound, in ``at_bound`` (its value is then the bound and its standard
        error NaN), not as a failure.
    """
    data = _as_data(data)
    w = data.omega
    E1 = data.E_storage
    lo_E0, hi_E0 = math.log(E1.min() / 100.0), math.log(2.0 * E1.min())
    lo_Ei, hi_Ei = math.log(E1.max() / 2.0), math.log(100.0 * E1.max())
    lo_t, hi_t = math.log(1e-3 / w.max()), math.log(1e3 / w.min())
    # coarse grid in (n, ln tau0) with the plateaus at the data's extremes
    p_E0, p_Ei = math.log(E1.min()), math.log(max(E1.max(), 1.0001 * E1.min()))
    best = []
    for n in (0.1, 0.2, 0.35, 0.6, 1.0, 1.6):
        for lt in np.linspace(lo_t + 2.0, hi_t - 2.0, 9):
            p = np.array([p_E0, p_Ei, n, lt])
            r = _mpl_residuals(p, data)
            best.append((float(r @ r), p))
    best.sort(key=lambda x: x[0])
    lower = [lo_E0, lo_Ei, _N_BOUNDS[0], lo_t]
    upper = [hi_E0, hi_Ei, _N_BOUNDS[1], hi_t]
    sol = None
    for _, p0 in best[:3]:
        p0 = np.clip(p0, np.array(lower) + 1e-9, np.array(upper) - 1e-9)
        s = least_squares(_mpl_residuals, p0, args=(data,), bounds=(lower, upper),
                          x_scale=[1.0, 1.0, 0.1, 1.0], xtol=1e-12, ftol=1e-12, gtol=1e-12,
                          max_nfev=400)
        if sol is None or s.cost < sol.cost:
            sol = s
    p = sol.x
    m, npar = sol.fun.size, p.size
    # a constant on a bound is not estimated by the data: flag it, give it no interval, and
    # compute the others' errors with it held fixed
    names = ("E0", "Einf", "n", "tau0")
    what = {"E0": ("min E'/100", "2 x min E'"), "Einf": ("max E'/2", "100 x max E'"),
            "n": (f"{_N_BOUNDS[0]:g}", f"{_N_BOUNDS[1]:g}"),
            "tau0": ("1e-3/max omega", "1e3/min omega")}
    at_bound = {}
    for i, name in enumerate(names):
        tol = 1e-6 * max(1.0, upper[i] - lower[i])
        if sol.active_mask[i] < 0 or p[i] - lower[i] <= tol:
            at_bound[name] = f"lower bound {what[name][0]}"
        elif sol.active_mask[i] > 0 or upper[i] - p[i] <= tol:
            at_bound[name] = f"upper bound {what[name][1]}"
    free = [i for i, name in enumerate(names) if name not in at_bound]
    dof = max(m - len(free), 1)
    s2 = 2.0 * sol.cost / dof
    J = sol.jac[:, free]
    sd = np.full(npar, np.nan)
    try:
        cov = s2 * np.linalg.pinv(J.T @ J)
        sd[free] = np.sqrt(np.clip(np.diag(cov), 0.0, None))
    except np.linalg.LinAlgError:  # pragma: no cover
        pass
    E0, Einf, n, tau0 = math.exp(p[0]), math.exp(p[1]), float(p[2]), math.exp(p[3])
    # log-parameter errors -> absolute (first order): d(e^x) = e^x dx
    stderr = {"E0": E0 * sd[0], "Einf": Einf * sd[1], "n": float(sd[2]), "tau0": tau0 * sd[3]}
    rel = {"E0": float(sd[0]), "Einf": float(sd[1]), "n": float(sd[2] / n),
           "tau0": float(sd[3])}
    E_model = MPLRetardation(E0, Einf, n, tau0).complex_modulus(w)
    quality = _quality(data, E_model)
    quality.update(rms_log=float(math.sqrt(2.0 * sol.cost / m)), dof=int(dof))
    return MPLFit(E0=E0, Einf=Einf, n=n, tau0=tau0, stderr=stderr, rel_stderr=rel,
                  quality=quality, success=bool(sol.success), message=str(sol.message),
                  at_bound=at_bound)


# ============================================================================ Maxwell

@dataclass
class MaxwellFit:
    """Result of :func:`fit_maxwell` (SI).

    Attributes
    ----------
    E0 : float
        Equilibrium (relaxed) spring [Pa].
    moduli, times : ndarray
        Arm moduli ``E_i >= 0`` [Pa] and relaxation times ``tau_i`` [s] (ascending); arms
        that NNLS set to zero are kept (their modulus is 0).
    quality : dict
        As in :class:`MPLFit` (relative residuals), plus ``active_arms``.
    """

    E0: float
    moduli: np.ndarray
    times: np.ndarray
    quality: dict = field(default_factory=dict)

    @property
    def Einf(self) -> float:
        """Glassy modulus ``E0 + sum E_i`` [Pa]."""
        return float(self.E0 + self.moduli.sum())

    @property
    def material(self) -> Prony:
        """The fitted Wiechert material (:class:`sweep.materials.Prony`, kind maxwell)."""
        keep = self.moduli > 0
        return Prony(self.moduli[keep], self.times[keep], E0=self.E0, kind="maxwell")

    def complex_modulus(self, omega) -> np.ndarray:
        """``E0 + sum E_i i w tau_i/(1 + i w tau_i)`` [Pa] at ``omega`` [rad/s]."""
        wt = np.asarray(omega, float)[:, None] * self.times[None, :]
        return self.E0 + (self.moduli[None, :] * (1j * wt) / (1.0 + 1j * wt)).sum(axis=1)

    def to_dict(self) -> dict:
        return {"E0": self.E0, "Einf": self.Einf, "moduli": self.moduli.tolist(),
                "times": self.times.tolist(), "quality": self.quality}


def _maxwell_design(omega, times, w1, w2, storage=True, loss=True):
    wt = omega[:, None] * times[None, :]
    den = 1.0 + wt**2
    blocks = []
    if storage:
        blocks.append(np.hstack([np.ones((omega.size, 1)), wt**2 / den]) * w1[:, None])
    if loss:
        blocks.append(np.hstack([np.zeros((omega.size, 1)), wt / den]) * w2[:, None])
    return np.vstack(blocks)


def _nnls_maxwell(omega, times, E1, E2, storage=True, loss=True):
    w1, w2 = 1.0 / E1, 1.0 / E2
    A = _maxwell_design(omega, times, w1, w2, storage, loss)
    b = np.concatenate(([np.ones_like(E1)] if storage else []) + ([np.ones_like(E2)] if loss else []))
    scale = np.linalg.norm(A, axis=0)
    scale[scale == 0.0] = 1.0
    x = nnls(A / scale, b, maxiter=50 * A.shape[1])[0] / scale
    return x[0], x[1:]


def fit_maxwell(data, arms: int = 18) -> MaxwellFit:
    """Generalized Maxwell fit with ``arms`` arms by non-negative least squares.

    Relaxation times log-spaced from ``1/omega_max`` to ``1/omega_min`` (the data's decades);
    ``E0`` and ``E_i >= 0`` minimize the sum of the squared RELATIVE residuals of ``E'`` and
    ``E''`` (each row divided by the measured value).

    Parameters
    ----------
    data : DMAData or (omega, E_storage, E_loss)
    arms : int
        Number of arms, in [1, 200].
    """
    data = _as_data(data)
    arms = check_int("maxwell", arms, 1, 200)
    w = data.omega
    times = np.logspace(-math.log10(w.max()), -math.log10(w.min()), arms)
    E0, Ei = _nnls_maxwell(w, times, data.E_storage, data.E_loss)
    fit = MaxwellFit(E0=float(E0), moduli=Ei, times=times)
    fit.quality = _quality(data, fit.complex_modulus(w))
    fit.quality["active_arms"] = int(np.count_nonzero(Ei > 0))
    return fit


# ============================================================================ Kramers-Kronig

@dataclass
class KKCheck:
    """Result of :func:`kramers_kronig_check`.

    Attributes
    ----------
    loss_predicted : ndarray
        ``E''`` [Pa] implied by ``E'`` through a causal (Wiechert) model, at the data's omega.
    rms_rel, max_rel : float
        rms and max of ``E''_predicted / E''_data - 1`` over the interior points (the first and
        last decade excluded: there the prediction depends on the unmeasured ends). Shown for
        information: where the loss tangent is small, a relative noise of ``E'`` is a much
        larger relative error of the ``E''`` it implies.
    rms_modulus : float
        rms of ``(E''_predicted - E''_data) / |E*|`` over the interior points: the statistic
        the decision uses (a noise of relative size s in ``E'`` and ``E''`` moves it by about
        s, whatever the loss tangent).
    noise : float
        The relative rms noise of ``E'`` and ``E''`` the data were stated to have.
    threshold : float
        The tolerance: largest ``rms_modulus`` accepted as consistent,
        ``KK_FLOOR + KK_NOISE_FACTOR * noise`` unless given.
    consistent : bool
        ``rms_modulus <= threshold``.
    """

    loss_predicted: np.ndarray
    rms_rel: float
    max_rel: float
    threshold: float
    consistent: bool
    interior_points: int
    rms_modulus: float = math.nan
    noise: float = math.nan

    def to_dict(self) -> dict:
        return {"rms_rel": self.rms_rel, "max_rel": self.max_rel,
                "rms_modulus": self.rms_modulus, "noise": self.noise,
                "threshold": self.threshold, "consistent": self.consistent,
                "interior_points": self.interior_points}


#: The KK tolerance on ``rms_modulus`` for noise-free data (the Wiechert representation and
#: the smoothing of E' leave at most 0.006 on MPL master curves of 6 to 21 decades) ...
KK_FLOOR = 0.02
#: ... plus this many times the stated relative noise (over 5 noise draws on MPL curves of
#: 6 to 21 decades with 1, 3 and 5 % noise, rms_modulus stayed below 1.3 x the noise).
KK_NOISE_FACTOR = 1.5
#: Width (standard deviation, decades) of the local quadratic smoothing of log E' before the
#: causal model is fitted to it: noise would otherwise be differentiated into E''.
KK_SMOOTH_DECADES = 0.5


def _smooth_log(lw, ly, x, width):
    """Local quadratic regression (Gaussian weights of standard deviation ``width``) of
    ``ly`` against ``lw``, evaluated at ``x``; where fewer than 5 points lie within about a
    width (sparse data), the monotone cubic interpolant instead."""
    spline = PchipInterpolator(lw, ly)
    out = np.empty_like(x)
    for i, xi in enumerate(x):
        wts = np.exp(-0.5 * ((lw - xi) / width) ** 2)
        if (wts > 0.3).sum() < 5:
            out[i] = spline(xi)
            continue
        sw = np.sqrt(wts)
        A = np.vstack([np.ones_like(lw), lw - xi, (lw - xi) ** 2]).T * sw[:, None]
        out[i] = np.linalg.lstsq(A, ly * sw, rcond=None)[0][0]
    return out


def storage_fall(data, noise: float = 0.01) -> dict | None:
    """The largest fall of the storage modulus between neighbouring frequencies, where it
    exceeds what the data's relative noise explains (two noisy points differ by sqrt(2)
    noise: 4 of those, and :data:`KK_FLOOR`); None otherwise. A linear viscoelastic solid's
    E' does not fall with frequency: such data are not what they claim (columns or units).

    Returns
    -------
    dict or None
        ``fall`` (relative to the lower frequency's E'), ``omega_from``, ``omega_to``
        [rad/s] and ``limit``.
    """
    data = _as_data(data)
    e1 = np.asarray(data.E_storage, float)
    drops = (e1[:-1] - e1[1:]) / e1[:-1]          # by ascending omega
    limit = KK_FLOOR + 4.0 * math.sqrt(2.0) * float(noise)
    if not drops.size:
        return None
    i = int(np.argmax(drops))
    if not drops[i] > limit:
        return None
    return {"fall": float(drops[i]), "omega_from": float(data.omega[i]),
            "omega_to": float(data.omega[i + 1]), "limit": limit}


def kramers_kronig_check(data, threshold: float | None = None, per_decade: float = 4.0,
                         noise: float = 0.01) -> KKCheck:
    """Linear Kramers-Kronig test of a measured complex modulus (module docstring).

    ``log E'`` is smoothed (local quadratic, :data:`KK_SMOOTH_DECADES`) and resampled; a
    Wiechert model with ``per_decade`` arms per decade, times spanning the data's decades
    widened by one decade each side, is fitted by NNLS to it alone; since any such model
    satisfies the KK relations, its loss modulus is the ``E''`` that KK implies (up to the
    unmeasured ends, hence the interior-only statistics). The data are consistent when the
    rms of ``(E''_implied - E''_data) / |E*|`` is at most the tolerance
    ``KK_FLOOR + KK_NOISE_FACTOR * noise``.

    Parameters
    ----------
    data : DMAData or (omega, E_storage, E_loss)
    threshold : float, optional
        The tolerance on ``rms_modulus`` (> 0); default from ``noise`` as above.
    per_decade : float
        Arms per decade (in [1, 20]).
    noise : float
        Relative rms noise of ``E'`` and ``E''`` (in [0, 0.5]; 0.01 = 1 %).
    """
    data = _as_data(data)
    noise = check_range("noise", noise, 0.0, 0.5)
    if threshold is None:
        threshold = KK_FLOOR + KK_NOISE_FACTOR * noise
    threshold = check_range("threshold", threshold, lo=0.0, lo_open=True)
    per_decade = check_range("per_decade", per_decade, 1.0, 20.0)
    w = data.omega
    lo, hi = -math.log10(w.max()) - 1.0, -math.log10(w.min()) + 1.0
    times = np.logspace(lo, hi, max(int(round((hi - lo) * per_decade)) + 1, 2))
    # E' resampled (monotone cubic in log-log) at 2 per_decade points per decade besides the
    # data, so that sparse data (a temperature sweep shifts unevenly) do not leave the arms
    # undetermined
    lw = np.log(w)
    keep = np.concatenate([[True], np.diff(lw) > 0])
    wr = np.union1d(w, np.logspace(math.log10(w.min()), math.log10(w.max()),
                                   max(int(math.log10(w.max() / w.min()) * 2 * per_decade), 2)))
    E1r = np.exp(_smooth_log(lw[keep], np.log(data.E_storage[keep]), np.log(wr),
                             KK_SMOOTH_DECADES * math.log(10.0)))
    E0, Ei = _nnls_maxwell(wr, times, E1r, np.ones_like(wr), loss=False)
    fit = MaxwellFit(E0=float(E0), moduli=Ei, times=times)
    pred = fit.complex_modulus(w).imag
    inner = (w >= 10.0 * w.min()) & (w <= w.max() / 10.0)
    if inner.sum() < 2:
        inner = np.ones_like(w, dtype=bool)
    r = pred[inner] / data.E_loss[inner] - 1.0
    rms = float(np.sqrt(np.mean(r**2)))
    rm = (pred[inner] - data.E_loss[inner]) / np.hypot(data.E_storage[inner],
                                                       data.E_loss[inner])
    rms_mod = float(np.sqrt(np.mean(rm**2)))
    return KKCheck(loss_predicted=pred, rms_rel=rms, max_rel=float(np.max(np.abs(r))),
                   threshold=threshold, consistent=bool(rms_mod <= threshold),
                   interior_points=int(inner.sum()), rms_modulus=rms_mod, noise=noise)


# ============================================================================ plot

def plot_dma(data, mpl: MPLFit | None, maxwell: MaxwellFit | None, out, name: str = "out"):
    """The paper's Fig. EE: E' and E'' vs omega, data and fits (needs the ``plot`` extra).

    Parameters
    ----------
    data : DMAData
    mpl : MPLFit or None
    maxwell : MaxwellFit or None
    out : str or Path
        The figure's file; its suffix is the format (:func:`sweep.analysis.plots.figure_path`).
    name : str, optional
        The option that gave ``out``, named in a one-line error (a format matplotlib cannot
        write, a path that cannot be written).

    Returns
    -------
    Path
        The path written.
    """
    from .plots import figure_path, pyplot, save_figure

    plt = pyplot()
    out = figure_path(name, out)
    data = _as_data(data)
    w = data.omega
    wf = np.logspace(math.log10(w.min()), math.log10(w.max()), 400)
    fig, axes = plt.subplots(1, 2, figsize=(10, 4.2))
    for ax, part, label in ((axes[0], "real", "E' [Pa]"), (axes[1], "imag", "E'' [Pa]")):
        y = data.E_storage if part == "real" else data.E_loss
        ax.loglog(w, y, "ko", mfc="none", ms=4, label="data")
        if mpl is not None:
            E = mpl.material.complex_modulus(wf)
            ax.loglog(wf, getattr(E, part), "b-", label=f"MPL (n = {mpl.n:.4g})")
        if maxwell is not None:
            E = maxwell.complex_modulus(wf)
            ax.loglog(wf, getattr(E, part), "r--", label=f"Maxwell, {maxwell.times.size} arms")
        ax.set_xlabel("omega [rad/s]")
        ax.set_ylabel(label)
        ax.grid(True, which="major", alpha=0.3)
    axes[0].legend(loc="upper left")
    ref = f" at T_ref = {data.T_ref:g} C" if data.T_ref is not None else ""
    fig.suptitle(f"DMA master curve{ref}: {os.path.basename(data.source)}")
    fig.tight_layout()
    return save_figure(fig, out, name)
