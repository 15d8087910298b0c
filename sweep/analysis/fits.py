r"""Analysis of sweep results: the paper's variables and fits (pandas in, pandas/dicts out).

Every function takes the runs table of :func:`sweep.load` (one row per scene) or arrays,
and returns a :class:`pandas.DataFrame` or a plain dict (JSON-ready: floats, lists, str).
No plotting here (see :mod:`sweep.paper.figures`). Units are those of docs/design.md section 2:

==================  ===========================================================
column              meaning
==================  ===========================================================
``gamma_eff``       ``P_po / P_JKR = pull_off / 1.5``, the normalized effective
                    surface energy (paper: Gamma_eff ~ P_po / P_JKR)
``vhat``            crack speed at pull-off ``v tau0 / l0`` (:func:`sweep.units.vhat_from_crack_speed`)
``rhat_pb``         ``r tau0 / d_ref = rate * h0`` (:func:`sweep.units.rhat_pb`; see there why)
``h0``              LJ range in ``d_ref`` (:func:`sweep.units.h0_hat`)
``l0``              PB process-zone length in ``a_ref`` (:func:`sweep.units.l0_hat`)
==================  ===========================================================

The fits:

* :func:`threshold_radius` / :func:`threshold_table`: the paper's threshold contact radius
  ``a0t``, the first ``a0`` where the spline through ``P_po(a0)`` has ``dP_po/da0 < 0.1``.
* :func:`collapse_fit` / :func:`collapse_sensitivity`: ``P_po = A a0t^B`` over the points
  below saturation (``P_po = 1.5/k``), with bootstrap 95 % intervals.
* :func:`vr_fit`: ``vhat = A rhat_PB^B`` (all points and the unsaturated ones).
* :func:`pb_comparison`, :func:`best_alpha`: Persson-Brener ``Gamma_eff(vhat)`` against
  the BEM, and the ``alpha`` (paper: pi/9) that minimizes their difference.
* :func:`pb_power_law`, :func:`pb_regimes`: power-law descriptions of the PB curve (the
  paper's Fig. PB_BEM inset and Appendix B, Fig. B1).
"""
from __future__ import annotations

import math

import numpy as np
import pandas as pd
from scipy.interpolate import CubicSpline
from scipy.optimize import brentq, minimize_scalar

from .. import units
from ..errors import InputError, check_positive, check_range
from ..scene import SCENE_AXES
from ..theory import jkr_pull_off, pb_gamma_eff, pb_gamma_eff_spectrum

__all__ = [
    "paper_variables",
    "finished",
    "power_law_fit",
    "threshold_radius",
    "threshold_table",
    "collapse_fit",
    "collapse_sensitivity",
    "threshold_analysis",
    "paper_protocol_fit",
    "per_n_fits",
    "radius_unit_check",
    "vr_fit",
    "pb_gamma_eff_scene",
    "pb_points",
    "pb_comparison",
    "best_alpha",
    "vr_analysis",
    "vr_paper_range",
    "vr_local_slope",
    "alpha_per_k",
    "bem_power_law",
    "pb_power_law",
    "pb_regimes",
]

#: The paper's rule for the threshold radius: dP_po/da0 below this (section "Threshold ...").
THRESHOLD_SLOPE = 0.1
#: Default share of the saturation 1.5/k below which a point counts as unsaturated.
SATURATION_FRACTION = 0.9
#: Bootstrap resamples and confidence level of every interval.
N_BOOT = 2000
#: the fewest points, and valid bootstrap resamples, from which :func:`power_law_fit` gives
#: an interval (below, None: a percentile of a handful of resamples of 3-5 points is no 95 %
#: interval)
MIN_BOOT_POINTS, MIN_BOOT_RESAMPLES = 6, 100
CONFIDENCE = 0.95

_GROUP = ["material", "n", "k", "mu", "rate"]


def _require_columns(df: pd.DataFrame, columns, what: str) -> None:
    missing = [c for c in columns if c not in df.columns]
    if missing:
        raise InputError(f"{what} needs the columns {', '.join(missing)} (a sweep.load table)")


def finished(df: pd.DataFrame) -> pd.DataFrame:
    """The rows with ``status == "ok"`` and a finite pull-off (failed scenes dropped)."""
    _require_columns(df, ["status", "pull_off"], "finished")
    keep = (df["status"] == "ok") & np.isfinite(df["pull_off"].to_numpy(dtype=float))
    return df.loc[keep].reset_index(drop=True)


def paper_variables(df: pd.DataFrame, alpha: float = units.ALPHA_PB) -> pd.DataFrame:
    r"""The paper's dimensionless variables of each scene, recomputed from the raw results.

    Parameters
    ----------
    df : DataFrame
        Runs table (:func:`sweep.load`) with at least ``mu, rate, pull_off, crack_speed``.
    alpha : float
        PB coefficient ``sigma_c / sigma_0`` (default pi/9) entering ``l0`` and ``vhat``.

    Returns
    -------
    DataFrame
        A copy of ``df`` with the columns ``gamma_eff = pull_off / 1.5``, ``vhat``,
        ``rhat_pb``, ``h0``, ``l0`` (units: module docstring) set from
        :mod:`sweep.units` (``vhat`` and ``rhat_pb`` overwrite the stored ones, which use
        alpha = pi/9, so that another ``alpha`` is honoured).
    """
    _require_columns(df, ["mu", "rate", "pull_off", "crack_speed"], "paper_variables")
    alpha = check_positive("alpha", alpha)
    out = df.copy()
    mu = out["mu"].to_numpy(dtype=float)
    out["gamma_eff"] = out["pull_off"].to_numpy(dtype=float) / jkr_pull_off()
    out["h0"] = [units.h0_hat(m) for m in mu]
    out["l0"] = [units.l0_hat(m, alpha) for m in mu]
    out["vhat"] = out["crack_speed"].to_numpy(dtype=float) / out["l0"].to_numpy()
    out["rhat_pb"] = out["rate"].to_numpy(dtype=float) * out["h0"].to_numpy()
    return out


# --------------------------------------------------------------------------------------------
# power laws
# --------------------------------------------------------------------------------------------
def power_law_fit(x, y, n_boot: int = N_BOOT, seed: int = 0,
                  confidence: float = CONFIDENCE) -> dict:
    r"""Least-squares power law ``y = A x^B`` in log-log space, with bootstrap intervals.

    .. math:: \ln y = \ln A + B \ln x

    The intervals are percentile intervals of ``n_boot`` refits on the points resampled
    with replacement (resamples whose ``x`` are all equal are skipped), given only from
    :data:`MIN_BOOT_POINTS` points and :data:`MIN_BOOT_RESAMPLES` valid resamples: with 4
    points (two near-equal x) the "interval" of B had been [2.2, 204], and ``--boot 1`` an
    interval that excluded the estimate.

    Parameters
    ----------
    x, y : array_like
        Positive abscissae and ordinates (at least 3 points, at least 2 distinct ``x``).
    n_boot : int
        Bootstrap resamples (0: no intervals).
    seed : int
        Seed of the resampling (the result is reproducible).
    confidence : float
        Two-sided level of the intervals, in (0, 1).

    Returns
    -------
    dict
        ``prefactor`` A, ``exponent`` B, ``prefactor_ci``, ``exponent_ci`` ([lo, hi] or
        None: no resampling, or too few points or resamples), ``n_points``,
        ``rms_log_residual`` (RMS of ``ln y - ln(A x^B)``).
    """
    x = np.asarray(x, dtype=float).ravel()
    y = np.asarray(y, dtype=float).ravel()
    if x.size != y.size:
        raise InputError(f"x and y must have equal lengths (got {x.size} and {y.size})")
    if x.size < 3:
        raise InputError(f"a power-law fit needs at least 3 points (got {x.size})")
    if np.unique(x).size < 2:
        raise InputError(f"a power-law fit needs at least 2 distinct x (got {x.size} points, "
                         f"all at x = {x[0]:.6g})")
    if not (np.all(x > 0) and np.all(y > 0) and np.all(np.isfinite(x * y))):
        raise InputError("a power-law fit needs finite positive x and y")
    confidence = check_range("confidence", confidence, 0.0, 1.0, lo_open=True, hi_open=True)
    lx, ly = np.log(x), np.log(y)
    slope, intercept = np.polyfit(lx, ly, 1)
    resid = ly - (intercept + slope * lx)
    out = {
        "prefactor": float(np.exp(intercept)),
        "exponent": float(slope),
        "prefactor_ci": None,
        "exponent_ci": None,
        "n_points": int(x.size),
        "rms_log_residual": float(np.sqrt(np.mean(resid**2))),
    }
    if n_boot > 0 and x.size >= MIN_BOOT_POINTS:
        rng = np.random.default_rng(seed)
        idx = rng.integers(0, x.size, size=(int(n_boot), x.size))
        bx, by = lx[idx], ly[idx]
        mx, my = bx.mean(axis=1), by.mean(axis=1)
        var = ((bx - mx[:, None]) ** 2).sum(axis=1)
        ok = var > 1e-14 * max(1.0, float(np.var(lx)) * x.size)
        b = ((bx - mx[:, None]) * (by - my[:, None])).sum(axis=1)[ok] / var[ok]
        a = np.exp(my[ok] - b * mx[ok])
        q = [50.0 * (1.0 - confidence), 50.0 * (1.0 + confidence)]
        if b.size >= MIN_BOOT_RESAMPLES:
            out["prefactor_ci"] = [float(v) for v in np.percentile(a, q)]
            out["exponent_ci"] = [float(v) for v in np.percentile(b, q)]
    return out


# --------------------------------------------------------------------------------------------
# threshold contact radius
# --------------------------------------------------------------------------------------------
def threshold_radius(a0, pull_off, slope: float = THRESHOLD_SLOPE) -> dict:
    r"""Threshold contact radius of one ``P_po(a0)`` curve by the paper's rule.

    A natural cubic spline interpolates the points; ``a0t`` is the first ``a0`` (scanning
    up from the smallest) where ``dP_po/da0 < slope`` (the crossing is located by root
    finding on the spline derivative). Later overshoot or recovery does not matter: the
    first crossing counts, as in the paper.

    Parameters
    ----------
    a0 : array_like
        Initial contact radii (a_ref, max-tension radius), at least 4 distinct values.
    pull_off : array_like
        Pull-off forces ``P_po`` (pi dg R) at those radii.
    slope : float
        The derivative criterion (paper: 0.1, in pi dg R / a_ref).

    Returns
    -------
    dict
        ``a0t`` (NaN if the slope never drops below ``slope``), ``pull_off_at_a0t`` (spline
        value there), ``status``: ``"interior"`` (a crossing between grid points),
        ``"at_lower_edge"`` (slope already below at the smallest a0: a0t <= min a0, reported
        as min a0) or ``"not_reached"``; ``peak_a0`` and ``peak_pull_off`` (the largest
        pull-off on the spline) and ``overshoot`` = peak / pull-off at the largest a0 - 1.
    """
    a = np.asarray(a0, dtype=float).ravel()
    p = np.asarray(pull_off, dtype=float).ravel()
    if a.size != p.size:
        raise InputError(f"a0 and pull_off must have equal lengths (got {a.size} and {p.size})")
    order = np.argsort(a)
    a, p = a[order], p[order]
    if np.unique(a).size != a.size or a.size < 4:
        raise InputError(
            f"a0 must hold at least 4 distinct radii for the threshold spline (got {a.size})"
        )
    slope = check_positive("slope", slope)
    spline = CubicSpline(a, p, bc_type="natural")
    deriv = spline.derivative()
    fine = np.linspace(a[0], a[-1], 200 * a.size)
    d = deriv(fine) - slope
    below = np.nonzero(d < 0.0)[0]
    peak_i = int(np.argmax(spline(fine)))
    out = {
        "a0t": math.nan, "pull_off_at_a0t": math.nan, "status": "not_reached",
        "peak_a0": float(fine[peak_i]), "peak_pull_off": float(spline(fine[peak_i])),
    }
    out["overshoot"] = out["peak_pull_off"] / float(p[-1]) - 1.0
    if below.size:
        i = int(below[0])
        if i == 0:
            a0t, status = float(a[0]), "at_lower_edge"
        else:
            a0t = float(brentq(lambda s: float(deriv(s)) - slope, fine[i - 1], fine[i],
                               xtol=1e-10))
            status = "interior"
        out.update(a0t=a0t, pull_off_at_a0t=float(spline(a0t)), status=status)
    return out


def threshold_table(df: pd.DataFrame, slope: float = THRESHOLD_SLOPE) -> pd.DataFrame:
    """The threshold radius of every ``(material, n, k, mu, rate)`` group of a sweep.

    Parameters
    ----------
    df : DataFrame
        Runs table of an ``a0`` sweep (:func:`sweep.load`); failed scenes are dropped.
    slope : float
        The derivative criterion of :func:`threshold_radius`.

    Returns
    -------
    DataFrame
        One row per group with at least 4 radii: the group keys, ``a0t``,
        ``pull_off_at_a0t`` (P at a0t), ``pull_off_plateau`` (at the largest a0),
        ``a0t_inner`` (the h = h0 radius of the initial state at a0t, interpolated in the
        scenes' ``a0_inner``), ``status``, ``peak_a0``, ``peak_pull_off``, ``overshoot``,
        ``n_a0``, ``saturation`` (1.5/k). Sorted by n then rate.
    """
    _require_columns(df, _GROUP + ["a0", "a0_inner"], "threshold_table")
    ok = finished(df)
    rows = []
    for key, g in ok.groupby(_GROUP, sort=True):
        g = g.sort_values("a0").drop_duplicates("a0")
        if len(g) < 4:
            continue
        a0 = g["a0"].to_numpy(dtype=float)
        res = threshold_radius(a0, g["pull_off"].to_numpy(dtype=float), slope)
        inner = (float(np.interp(res["a0t"], a0, g["a0_inner"].to_numpy(dtype=float)))
                 if np.isfinite(res["a0t"]) else math.nan)
        rows.append({**dict(zip(_GROUP, key)), "a0t": res["a0t"],
                     "pull_off_at_a0t": res["pull_off_at_a0t"],
                     "pull_off_plateau": float(g["pull_off"].iloc[-1]), "a0t_inner": inner,
                     "status": res["status"], "peak_a0": res["peak_a0"],
                     "peak_pull_off": res["peak_pull_off"], "overshoot": res["overshoot"],
                     "n_a0": int(len(g)), "saturation": jkr_pull_off() / float(key[2])})
    if not rows:
        raise InputError("threshold_table needs groups (n, k, mu, rate) with at least 4 radii a0")
    return pd.DataFrame(rows).sort_values(["material", "n", "k", "rate"]).reset_index(drop=True)


def _collapse_points(table: pd.DataFrame, saturation_fraction: float, min_rate: float,
                     ordinate: str, radius: str) -> pd.DataFrame:
    sel = table[(table["status"] == "interior") & (table["rate"] >= min_rate * (1 - 1e-9))]
    return sel[sel[ordinate] < saturation_fraction * sel["saturation"]]


def collapse_fit(table: pd.DataFrame, saturation_fraction: float = SATURATION_FRACTION,
                 min_rate: float = 0.0, ordinate: str = "pull_off_at_a0t",
                 radius: str = "a0t", n_boot: int = N_BOOT, seed: int = 0) -> dict:
    r"""The collapse power law ``P_po = A a0t^B`` of the threshold points (paper: 0.3, 2.7).

    Points enter when their threshold is an interior crossing (``status == "interior"``:
    an ``a0t`` at the grid's lower edge is only an upper bound), their rate is at least
    ``min_rate`` and their pull-off is below ``saturation_fraction * 1.5/k`` (on the
    plateau ``a0t`` no longer follows the power law).

    Parameters
    ----------
    table : DataFrame
        :func:`threshold_table` output.
    saturation_fraction : float
        Keep points with ``P < saturation_fraction * 1.5/k`` (> 1 keeps every point).
    min_rate : float
        Smallest unloading rate r-hat kept.
    ordinate : {"pull_off_at_a0t", "pull_off_plateau"}
        The pull-off at the threshold (spline) or at the largest a0 of the group.
    radius : {"a0t", "a0t_inner"}
        The threshold as max-tension radius (the project's a0) or as the h = h0 radius.

    Returns
    -------
    dict
        :func:`power_law_fit` output plus the selection (``saturation_fraction``,
        ``min_rate``, ``ordinate``, ``radius``).
    """
    sel = _collapse_points(table, saturation_fraction, min_rate, ordinate, radius)
    fit = power_law_fit(sel[radius], sel[ordinate], n_boot=n_boot, seed=seed)
    return {**fit, "saturation_fraction": float(saturation_fraction),
            "min_rate": float(min_rate), "ordinate": ordinate, "radius": radius}


#: The point selections of the sensitivity table: (label, saturation fraction, min rate,
#: ordinate). The first is the chosen rule.
SENSITIVITY_RULES = (
    ("P(a0t) < 0.9 * 1.5/k (chosen)", 0.9, 0.0, "pull_off_at_a0t"),
    ("P(a0t) < 0.75 * 1.5/k", 0.75, 0.0, "pull_off_at_a0t"),
    ("P(a0t) < 0.95 * 1.5/k", 0.95, 0.0, "pull_off_at_a0t"),
    ("all interior crossings", math.inf, 0.0, "pull_off_at_a0t"),
    ("P(a0t) < 0.9 * 1.5/k, rate >= 10", 0.9, 10.0, "pull_off_at_a0t"),
    ("P(a0t) < 0.9 * 1.5/k, rate >= 100", 0.9, 100.0, "pull_off_at_a0t"),
    ("P plateau (largest a0) < 0.9 * 1.5/k", 0.9, 0.0, "pull_off_plateau"),
)


def collapse_sensitivity(table: pd.DataFrame, rules=SENSITIVITY_RULES, n_boot: int = N_BOOT,
                         seed: int = 0) -> list[dict]:
    """The collapse fit under each point selection of ``rules`` (label, fraction, min rate,
    ordinate); one dict per rule: ``rule``, ``prefactor``, ``exponent``, their ``_ci``,
    ``n_points``, ``prefactor_inner`` (A for the h = h0 radius). Rules with fewer than 3
    points give NaN, with the points they have (it said 0 where 2 qualified)."""
    out = []
    for label, frac, min_rate, ordinate in rules:
        row = {"rule": label}
        try:
            f = collapse_fit(table, frac, min_rate, ordinate, "a0t", n_boot, seed)
            fi = collapse_fit(table, frac, min_rate, ordinate, "a0t_inner", 0, seed)
            row.update(prefactor=f["prefactor"], exponent=f["exponent"],
                       prefactor_ci=f["prefactor_ci"], exponent_ci=f["exponent_ci"],
                       n_points=f["n_points"], prefactor_inner=fi["prefactor"],
                       exponent_inner=fi["exponent"])
        except InputError:
            have = len(_collapse_points(table, frac, min_rate, ordinate, "a0t"))
            row.update(prefactor=math.nan, exponent=math.nan, prefactor_ci=None,
                       exponent_ci=None, n_points=int(have), prefactor_inner=math.nan,
                       exponent_inner=math.nan)
        out.append(row)
    return out


#: The paper's protocol of the collapse fit (section "Threshold contact radius"), each choice
#: with the sentence of the paper it comes from (:func:`paper_protocol_fit`).
PAPER_THRESHOLD_PROTOCOL = {
    "min_rate": 10.0**0.5,
    "saturation_fraction": 0.5,
    "ordinate": "pull_off_at_a0t",
    "radius": "a0t",
}
PAPER_THRESHOLD_SOURCES = (
    ("rate >= 10^0.5", '"Notice that, the smallest unloading rate considered in our analysis is '
     r'$\widehat{r}\approx3$ (see Fig. Threshold (b), inset) as for quasi static unloading the '
     r'elastic solution is retrieved and $\widehat{P}_{po}$ will not depend on $\widehat{a}_{0}$."'),
    ("P_po(a0t) < 0.5 x 1.5/k", '"they collapse for all the exponents n into a single power law '
     r'curve that we find to be $\widehat{P}_{po}=0.3\widehat{a}_{0t}^{2.7}$ ..., which clearly '
     r'saturates when the maximum enhancement $\widehat{P}_{po}=\widehat{P}_{JKR}/k=1.5/k$ is '
     'reached" and "the transition from the power-law behaviour to the plateau is faster for '
     'materials with large material exponent n": the line is fitted where the points follow '
     'the power law, below the transition. The paper states no number for the cut; 0.5 of the '
     'saturation is this project\'s reading (the table of cuts shows what another gives)'),
    ("ordinate P_po at a0t", '"set the condition dP_po/da0 < 0.1 to determine a threshold '
     'contact radius a0t, above which we considered the pull-off force is converged" and "if '
     'the data are represented as normalized pull-off force at convergence as a function of '
     'a0t": the pull-off where convergence is declared (the spline at a0t)'),
)
#: The saturation cuts of the paper protocol's sensitivity table (min rate kept at 10^0.5).
PAPER_PROTOCOL_CUTS = (0.5, 0.6, 0.75, 0.9)


def _fit_selected(sel: pd.DataFrame, ordinate: str, radius: str, n_boot: int, seed: int,
                  fixed_exponent: float | None) -> dict:
    """Power law of the selected threshold points, the same in the radius unit without pi
    (``a0t pi^(1/3)``: (R^2 dg/E0*)^(1/3) instead of a_ref = (pi R^2 dg/E0*)^(1/3)), and the
    prefactor at a fixed exponent (least squares of ln A alone) if one is given."""
    x = sel[radius].to_numpy(dtype=float)
    y = sel[ordinate].to_numpy(dtype=float)
    fit = power_law_fit(x, y, n_boot=n_boot, seed=seed)
    no_pi = power_law_fit(x * math.pi ** (1.0 / 3.0), y, n_boot=n_boot, seed=seed)
    out = {"A": fit["prefactor"], "B": fit["exponent"], "A_ci": fit["prefactor_ci"],
           "B_ci": fit["exponent_ci"], "A_no_pi": no_pi["prefactor"],
           "A_no_pi_ci": no_pi["prefactor_ci"], "n_points": fit["n_points"],
           "rms_log_residual": fit["rms_log_residual"]}
    if fixed_exponent is not None:
        b = float(fixed_exponent)
        out["B_fixed"] = b
        out["A_at_B_fixed"] = float(np.exp(np.mean(np.log(y) - b * np.log(x))))
        out["A_no_pi_at_B_fixed"] = out["A_at_B_fixed"] * math.pi ** (-b / 3.0)
    return out


def per_n_fits(table: pd.DataFrame, saturation_fraction: float, min_rate: float = 0.0,
               ordinate: str = "pull_off_at_a0t", n_boot: int = N_BOOT,
               seed: int = 0) -> list[dict]:
    """The collapse fit of each material exponent n alone, with the selection of
    :func:`collapse_fit`: one dict per n (``n``, ``A``, ``B``, ``A_ci``, ``B_ci``,
    ``n_points``); an n with fewer than 3 points (or 2 distinct radii) gives NaN."""
    sel = _collapse_points(table, saturation_fraction, min_rate, ordinate, "a0t")
    out = []
    for n in sorted(table["n"].unique()):
        g = sel[sel["n"] == n]
        try:
            f = power_law_fit(g["a0t"], g[ordinate], n_boot=n_boot, seed=seed)
            out.append({"n": float(n), "A": f["prefactor"], "B": f["exponent"],
                        "A_ci": f["prefactor_ci"], "B_ci": f["exponent_ci"],
                        "n_points": f["n_points"]})
        except InputError:
            out.append({"n": float(n), "A": math.nan, "B": math.nan, "A_ci": None,
                        "B_ci": None, "n_points": int(len(g))})
    return out


def paper_protocol_fit(table: pd.DataFrame, protocol: dict | None = None,
                       paper_exponent: float | None = None, n_boot: int = N_BOOT,
                       seed: int = 0) -> dict:
    r"""The collapse fit ``P_po = A a0t^B`` under the paper's protocol.

    The selection (:data:`PAPER_THRESHOLD_PROTOCOL`, sources in
    :data:`PAPER_THRESHOLD_SOURCES`): interior thresholds (as :func:`collapse_fit`), rates
    ``r-hat >= 10^0.5`` (the paper: "the smallest unloading rate considered in our analysis
    is r-hat ~ 3"), pull-off at a0t below ``0.5 x 1.5/k`` (the power law below its
    saturation; the cut itself is this project's reading).

    Parameters
    ----------
    table : DataFrame
        :func:`threshold_table` output.
    protocol : dict, optional
        Overrides of :data:`PAPER_THRESHOLD_PROTOCOL` (``min_rate``, ``saturation_fraction``,
        ``ordinate``, ``radius``).
    paper_exponent : float, optional
        An exponent at which the prefactor is also fitted alone (``A_at_B_fixed``; the report
        passes the paper's 2.7).

    Returns
    -------
    dict
        ``A``, ``B``, ``A_ci``, ``B_ci`` (95 % bootstrap), ``A_no_pi`` (+ ``_ci``: A with a0t
        in (R^2 dg/E0*)^(1/3), i.e. ``A pi^(-B/3)``), ``n_points``, ``rms_log_residual``,
        ``rule`` (text), ``sources`` (the paper's sentences), the selection values,
        ``per_n`` (:func:`per_n_fits` under the same rule), ``cuts`` (the fit at each
        saturation cut of :data:`PAPER_PROTOCOL_CUTS` and with the plateau pull-off as
        ordinate), and with ``paper_exponent`` ``A_at_B_fixed``, ``A_no_pi_at_B_fixed``.
    """
    p = {**PAPER_THRESHOLD_PROTOCOL, **(protocol or {})}
    frac = check_positive("saturation_fraction", p["saturation_fraction"])
    min_rate = float(p["min_rate"])
    sel = _collapse_points(table, frac, min_rate, p["ordinate"], p["radius"])
    out = _fit_selected(sel, p["ordinate"], p["radius"], n_boot, seed, paper_exponent)
    out["rule"] = (f"the project's a0t (first a0 where the spline through P_po(a0) has "
                   f"dP_po/da0 < 0.1, interior crossings); points with rate r-hat >= "
                   f"{min_rate:.4g} and {p['ordinate']} < {frac:g} x 1.5/k; least squares in "
                   f"log-log; 95 % percentile intervals from {n_boot} bootstrap resamples")
    out["sources"] = [{"choice": c, "paper": q} for c, q in PAPER_THRESHOLD_SOURCES]
    out.update(min_rate=min_rate, saturation_fraction=frac, ordinate=p["ordinate"],
               radius=p["radius"])
    out["per_n"] = per_n_fits(table, frac, min_rate, p["ordinate"], n_boot, seed)
    cuts = []
    for ordinate in ("pull_off_at_a0t", "pull_off_plateau"):
        for c in PAPER_PROTOCOL_CUTS:
            row = {"ordinate": ordinate, "saturation_fraction": c, "min_rate": min_rate}
            try:
                f = _fit_selected(_collapse_points(table, c, min_rate, ordinate, p["radius"]),
                                  ordinate, p["radius"], n_boot, seed, None)
                row.update({key: f[key] for key in ("A", "B", "A_ci", "B_ci", "A_no_pi",
                                                    "n_points")})
            except InputError:
                row.update(A=math.nan, B=math.nan, A_ci=None, B_ci=None, A_no_pi=math.nan,
                           n_points=0)
            cuts.append(row)
    out["cuts"] = cuts
    return out


def radius_unit_check(table: pd.DataFrame, prefactor: float, exponent: float,
                      saturation_fraction: float = 0.6, min_rate: float = 0.0) -> dict:
    r"""Which radius a published line ``P = prefactor a^exponent`` gives for our pull-offs.

    For each interior threshold point with ``P_po(a0t) < saturation_fraction x 1.5/k`` the
    radius of the line at the same pull-off, ``a_line = (P/prefactor)^(1/exponent)``, is
    compared with our ``a0t``: a constant ratio ``a_line / a0t`` says the two differ by a
    unit (``pi^(1/3) = 1.465`` is the ratio of a_ref = (pi R^2 dg/E0*)^(1/3) to
    (R^2 dg/E0*)^(1/3)); a constant difference ``a_line - a0t`` would say an offset. Both are
    reported with their spread and a straight line ``a_line = c0 + c1 a0t`` through the
    points. An inference, not a measurement of the paper's unit.

    Returns
    -------
    dict
        ``n_points``, ``ratio_mean``, ``ratio_std``, ``ratio_min``, ``ratio_max``,
        ``pi_cbrt``, ``offset_min``, ``offset_max``, ``line_intercept``, ``line_slope``,
        the inputs.
    """
    prefactor = check_positive("prefactor", prefactor)
    exponent = check_positive("exponent", exponent)
    sel = _collapse_points(table, saturation_fraction, min_rate, "pull_off_at_a0t", "a0t")
    if len(sel) < 3:
        raise InputError("radius_unit_check needs at least 3 threshold points below the cut")
    a = sel["a0t"].to_numpy(dtype=float)
    a_line = (sel["pull_off_at_a0t"].to_numpy(dtype=float) / prefactor) ** (1.0 / exponent)
    ratio, offset = a_line / a, a_line - a
    slope, icept = np.polyfit(a, a_line, 1)
    return {"n_points": int(a.size), "ratio_mean": float(ratio.mean()),
            "ratio_std": float(ratio.std(ddof=1)), "ratio_min": float(ratio.min()),
            "ratio_max": float(ratio.max()), "pi_cbrt": math.pi ** (1.0 / 3.0),
            "offset_min": float(offset.min()), "offset_max": float(offset.max()),
            "line_intercept": float(icept), "line_slope": float(slope),
            "a0t_range": [float(a.min()), float(a.max())],
            "prefactor": prefactor, "exponent": exponent,
            "saturation_fraction": float(saturation_fraction)}


def threshold_analysis(df: pd.DataFrame, slope: float = THRESHOLD_SLOPE,
                       saturation_fraction: float = SATURATION_FRACTION,
                       n_boot: int = N_BOOT, seed: int = 0,
                       paper_fit: tuple[float, float] | None = None) -> dict:
    """Everything ``fit.json`` of the threshold campaign holds, from its runs table.

    The project's rule (:data:`SENSITIVITY_RULES` [0]) gives the headline numbers; the
    paper's protocol (:func:`paper_protocol_fit`) is beside it in ``paper_protocol``. With
    ``paper_fit`` (A, B) of a published line, ``paper_protocol`` also holds the prefactor at
    the published exponent and ``radius_unit`` the radius-unit check
    (:func:`radius_unit_check`) of that line against these points.

    Returns
    -------
    dict
        ``prefactor``, ``exponent``, ``prefactor_ci``, ``exponent_ci``, ``n_points``,
        ``rms_log_residual`` (chosen rule: :data:`SENSITIVITY_RULES` [0]), ``rule`` (text),
        ``prefactor_inner`` (+ ``_ci``, ``exponent_inner``: the same points with a0t the
        h = h0 radius), ``prefactor_no_pi`` (A for a0 in (R^2 dg/E0*)^(1/3), i.e.
        ``A pi^(-B/3)``), ``sensitivity`` (:func:`collapse_sensitivity`), ``per_n`` (the
        chosen rule per n, :func:`per_n_fits`), ``paper_protocol``
        (:func:`paper_protocol_fit`), ``radius_unit`` (with ``paper_fit``), ``table``
        (rows of n, rate, a0t, P_at_a0t, ..., ``in_fit``, ``in_paper_fit``),
        ``overshoots`` (groups whose spline peak exceeds the largest-a0 pull-off by more
        than 5 %), ``scenes``, ``failed``.
    """
    table = threshold_table(df, slope)
    fit = collapse_fit(table, saturation_fraction, 0.0, "pull_off_at_a0t", "a0t", n_boot, seed)
    inner = collapse_fit(table, saturation_fraction, 0.0, "pull_off_at_a0t", "a0t_inner",
                         n_boot, seed)
    rule = (f"a0t = first a0 where the natural cubic spline through P_po(a0) has dP_po/da0 < "
            f"{slope:g}; fit P_po(a0t) = A a0t^B by least squares in log-log over the groups "
            f"whose crossing lies inside the a0 grid and whose P_po(a0t) < "
            f"{saturation_fraction:g} * 1.5/k; 95 % percentile intervals from {n_boot} "
            f"bootstrap resamples of the points")
    table_rows = [
        {"n": r.n, "k": r.k, "mu": r.mu, "material": r.material, "rate": r.rate, "a0t": r.a0t,
         "P_at_a0t": r.pull_off_at_a0t, "P_plateau": r.pull_off_plateau,
         "a0t_inner": r.a0t_inner, "saturation": r.saturation, "status": r.status,
         "peak_a0": r.peak_a0,
         "peak_pull_off": r.peak_pull_off, "overshoot": r.overshoot,
         "in_fit": bool(r.status == "interior"
                        and r.pull_off_at_a0t < saturation_fraction * r.saturation)}
        for r in table.itertuples()
    ]
    try:
        paper = paper_protocol_fit(table, paper_exponent=None if paper_fit is None
                                   else paper_fit[1], n_boot=n_boot, seed=seed)
        pp = _collapse_points(table, paper["saturation_fraction"], paper["min_rate"],
                              paper["ordinate"], paper["radius"])
        in_paper = set(zip(pp["n"], pp["rate"]))
    except InputError:           # fewer than 3 points under the paper's protocol
        paper, in_paper = None, set()
    for row in table_rows:
        row["in_paper_fit"] = (row["n"], row["rate"]) in in_paper
    extra = {}
    if paper_fit is not None:
        try:
            extra["radius_unit"] = radius_unit_check(table, *paper_fit)
        except InputError:
            extra["radius_unit"] = None
    over = table[table["overshoot"] > 0.05]
    return {
        **extra,
        "per_n": per_n_fits(table, saturation_fraction, 0.0, "pull_off_at_a0t", n_boot, seed),
        "paper_protocol": paper,
        "prefactor": fit["prefactor"], "exponent": fit["exponent"],
        "prefactor_ci": fit["prefactor_ci"], "exponent_ci": fit["exponent_ci"],
        "n_points": fit["n_points"], "rms_log_residual": fit["rms_log_residual"],
        "rule": rule, "slope_criterion": slope, "saturation_fraction": saturation_fraction,
        "prefactor_inner": inner["prefactor"], "prefactor_inner_ci": inner["prefactor_ci"],
        "exponent_inner": inner["exponent"], "exponent_inner_ci": inner["exponent_ci"],
        "prefactor_no_pi": fit["prefactor"] * math.pi ** (-fit["exponent"] / 3.0),
        "sensitivity": collapse_sensitivity(table, n_boot=n_boot, seed=seed),
        "table": table_rows,
        "overshoots": [{"n": r.n, "rate": r.rate, "peak_a0": r.peak_a0,
                        "peak_pull_off": r.peak_pull_off,
                        "pull_off_plateau": r.pull_off_plateau} for r in over.itertuples()],
        "scenes": int(len(df)), "failed": int((df["status"] != "ok").sum()),
    }


# --------------------------------------------------------------------------------------------
# crack speed versus rate, Persson-Brener against the BEM
# --------------------------------------------------------------------------------------------
def _unsaturated(d: pd.DataFrame, saturation_fraction: float) -> np.ndarray:
    return (d["pull_off"] < saturation_fraction * jkr_pull_off() / d["k"]).to_numpy()


def _vr_points(df: pd.DataFrame, alpha: float) -> pd.DataFrame:
    _require_columns(df, _GROUP + ["crack_speed"], "vr analysis")
    d = paper_variables(finished(df), alpha)
    d = d[(d["material"] == "mpl") & (d["vhat"] > 0) & (d["rhat_pb"] > 0)]
    if len(d) < 3:
        raise InputError("the v-r fit needs at least 3 finished MPL scenes with vhat > 0")
    return d.reset_index(drop=True)


def vr_fit(df: pd.DataFrame, saturation_fraction: float = SATURATION_FRACTION,
           alpha: float = units.ALPHA_PB, n_boot: int = N_BOOT, seed: int = 0) -> dict:
    r"""Crack speed at pull-off against unloading rate, ``vhat = A rhat_PB^B`` (paper 2.887,
    1.171), over the finished MPL scenes with ``vhat > 0``.

    Returns
    -------
    dict
        ``all`` and ``unsaturated`` (scenes with ``P_po < saturation_fraction * 1.5/k``),
        each a :func:`power_law_fit` dict.
    """
    d = _vr_points(df, alpha)
    uns = d[_unsaturated(d, saturation_fraction)]
    return {"all": _named_fit("all MPL points", d["rhat_pb"], d["vhat"], n_boot, seed),
            "unsaturated": _named_fit(f"unsaturated points (P_po < {saturation_fraction:g} * "
                                      f"1.5/k)", uns["rhat_pb"], uns["vhat"], n_boot, seed),
            "saturation_fraction": float(saturation_fraction)}


def _named_fit(what: str, x, y, n_boot: int, seed: int) -> dict:
    """:func:`power_law_fit` of the selection ``what``, which its InputError names."""
    try:
        return power_law_fit(x, y, n_boot, seed)
    except InputError as exc:
        raise InputError(f"{what}: {exc}") from None


def pb_gamma_eff_scene(material: str, n: float, k: float, vhat):
    """Persson-Brener ``Gamma_eff(vhat)`` of a scene's material: the MPL spectrum
    (:func:`sweep.theory.pb_gamma_eff`) or the SLS (one retardation time tau0)."""
    if material == "sls":
        return pb_gamma_eff_spectrum([1.0], [1.0], k, vhat)
    return pb_gamma_eff(n, k, vhat)


def _pb_of(d: pd.DataFrame, vhat: np.ndarray) -> np.ndarray:
    out = np.empty(len(d))
    for i, (m, n, k) in enumerate(zip(d["material"], d["n"], d["k"])):
        out[i] = pb_gamma_eff_scene(m, float(n), float(k), float(vhat[i]))
    return out


def pb_points(points: pd.DataFrame, prefactor: float, exponent: float) -> pd.DataFrame:
    """``points`` (:func:`paper_variables` rows, any material) with the columns
    ``vhat_predicted = prefactor rhat_PB^exponent``, ``gamma_pb_measured`` (PB at the
    measured vhat) and ``gamma_pb_predicted`` (PB at the predicted one)."""
    d = points.reset_index(drop=True).copy()
    d["vhat_predicted"] = prefactor * d["rhat_pb"].to_numpy(dtype=float) ** exponent
    d["gamma_pb_measured"] = _pb_of(d, d["vhat"].to_numpy(dtype=float))
    d["gamma_pb_predicted"] = _pb_of(d, d["vhat_predicted"].to_numpy())
    return d


def _error_summary(bem: np.ndarray, pb: np.ndarray) -> dict:
    rel = bem / pb - 1.0
    return {"n_points": int(rel.size),
            "share_within_15pct": float(np.mean(np.abs(rel) <= 0.15)),
            "median_abs_error": float(np.median(np.abs(rel))),
            "max_abs_error": float(np.max(np.abs(rel))),
            "rms_log_error": float(np.sqrt(np.mean(np.log(bem / pb) ** 2)))}


def pb_comparison(df: pd.DataFrame, prefactor: float, exponent: float,
                  alpha: float = units.ALPHA_PB) -> tuple[pd.DataFrame, dict]:
    r"""Persson-Brener against the BEM, two ways, for every finished MPL scene.

    ``measured``: ``Gamma_PB(vhat_BEM)`` against ``Gamma_BEM = P_po/1.5``; ``predicted``:
    ``Gamma_PB(A rhat_PB^B)`` (the crack speed predicted from the rate by a v-r fit, the
    paper's Fig. r_v). The relative error is ``Gamma_BEM / Gamma_PB - 1``.

    Returns
    -------
    (DataFrame, dict)
        The points (``gamma_eff``, ``gamma_pb_measured``, ``gamma_pb_predicted``,
        ``vhat_predicted`` and the scene keys) and, for each way, ``share_within_15pct``,
        ``median_abs_error``, ``max_abs_error``, ``rms_log_error``.
    """
    d = pb_points(_vr_points(df, alpha), prefactor, exponent)
    bem = d["gamma_eff"].to_numpy()
    return d, {"measured": _error_summary(bem, d["gamma_pb_measured"].to_numpy()),
               "predicted": _error_summary(bem, d["gamma_pb_predicted"].to_numpy()),
               "prefactor": float(prefactor), "exponent": float(exponent)}


def best_alpha(df: pd.DataFrame, bounds=(0.05, 2.0)) -> dict:
    r"""The ``alpha = sigma_c/sigma_0`` minimizing the BEM-vs-PB error (paper: pi/9).

    ``vhat`` scales as ``alpha^2`` (``l0 ~ 1/alpha^2``); the error minimized is the RMS of
    ``ln(Gamma_BEM / Gamma_PB(vhat_BEM(alpha)))`` over the finished MPL scenes (bounded
    scalar minimization over ``bounds``).

    Returns
    -------
    dict
        ``alpha_best``, ``alpha_best_over_paper`` (ratio to pi/9), ``rms_log_error`` at the
        best and at pi/9, ``share_within_15pct`` at the best.
    """
    d0 = _vr_points(df, units.ALPHA_PB)
    v0 = d0["vhat"].to_numpy()
    bem = d0["gamma_eff"].to_numpy()

    def err(alpha):
        pb = _pb_of(d0, v0 * (alpha / units.ALPHA_PB) ** 2)
        return float(np.sqrt(np.mean(np.log(bem / pb) ** 2)))

    res = minimize_scalar(err, bounds=bounds, method="bounded", options={"xatol": 1e-5})
    a = float(res.x)
    pb_best = _pb_of(d0, v0 * (a / units.ALPHA_PB) ** 2)
    return {"alpha_best": a, "alpha_best_over_paper": a / units.ALPHA_PB,
            "alpha_paper": units.ALPHA_PB, "rms_log_error_best": float(res.fun),
            "rms_log_error_paper_alpha": err(units.ALPHA_PB),
            "share_within_15pct_best": float(np.mean(np.abs(bem / pb_best - 1) <= 0.15)),
            "error_measure": "RMS of ln(Gamma_BEM / Gamma_PB(vhat(alpha))) over MPL scenes"}


#: The paper's rate grid, r-hat = r tau0/h0 in [10^0, 10^6] (:func:`vr_paper_range`), and the
#: sentence it comes from.
PAPER_VR_RATE_RANGE = (1.0, 1.0e6)
PAPER_VR_SOURCE = (
    r'"every marker shown corresponds to the threshold contact radius obtained for that '
    r'material exponent n and at that given normalized unloading rate $\widehat{r} \in '
    r'[10^0,10^6]$" (section "Threshold contact radius"); the v-r section states no range of '
    r'its own ("scales approximately as v = 2.887 r_PB^1.171 over about 10 orders of magnitude '
    r'in term of unloading rate"), and Fig. r_v shows "the same simulations results" for '
    r'n = [0.4, 0.6, 0.8, 1.6] and k = [0.01, 0.05, 0.1], saturated points included')
#: Further rate ranges of the v-r sensitivity rows (r-hat, inclusive).
VR_RANGES = ((1.0, 1.0e4), (0.1, 1.0e6))


def vr_paper_range(df: pd.DataFrame, rate_range=PAPER_VR_RATE_RANGE,
                   alpha: float = units.ALPHA_PB, n_boot: int = N_BOOT, seed: int = 0) -> dict:
    r"""``vhat = A rhat_PB^B`` over the finished MPL scenes whose rate r-hat lies in
    ``rate_range`` (default the paper's grid [1, 1e6], :data:`PAPER_VR_SOURCE`), all k and n,
    saturated points included as in the paper's Fig. r_v.

    Returns
    -------
    dict
        ``prefactor``, ``exponent``, ``prefactor_ci``, ``exponent_ci``, ``n_points``,
        ``rms_log_residual``, ``rate_range``, ``rule`` (text), ``source`` (the paper's
        sentence) and ``ranges``: the same fit over each range of :data:`VR_RANGES`.
    """
    lo, hi = (float(x) for x in rate_range)
    if not 0.0 < lo < hi:
        raise InputError(f"rate_range must be two rates 0 < lo < hi (got {rate_range!r})")
    d = _vr_points(df, alpha)

    def fit_in(lo_, hi_):
        r = d["rate"].to_numpy(dtype=float)
        sel = d[(r >= lo_ * (1 - 1e-9)) & (r <= hi_ * (1 + 1e-9))]
        return _named_fit(f"MPL points at rates r-hat in [{lo_:g}, {hi_:g}]", sel["rhat_pb"],
                          sel["vhat"], n_boot, seed)

    fit = fit_in(lo, hi)
    ranges = []
    for lo_, hi_ in VR_RANGES:
        try:
            f = fit_in(lo_, hi_)
            ranges.append({"rate_range": [lo_, hi_], **{key: f[key] for key in (
                "prefactor", "exponent", "prefactor_ci", "exponent_ci", "n_points")}})
        except InputError:
            continue
    return {**fit, "rate_range": [lo, hi],
            "rule": (f"finished MPL scenes (every n and k of the campaign) with rate r-hat = r "
                     f"tau0/h0 in [{lo:g}, {hi:g}], saturated ones included; vhat = A "
                     f"rhat_PB^B by least squares in log-log, rhat_PB = rate * h0; 95 % "
                     f"percentile intervals from {n_boot} bootstrap resamples"),
            "source": PAPER_VR_SOURCE, "ranges": ranges}


def vr_local_slope(df: pd.DataFrame, alpha: float = units.ALPHA_PB) -> list[dict]:
    r"""How far the v-r data are from one power law: the local slope ``d ln vhat / d ln
    rhat_PB`` between neighbouring rates of each MPL group, and ``vhat / rhat_PB``.

    A group is one value of every scene axis but the rate (n, k, mu, a0 or delta0, ...):
    the v-r campaign has one a0 per (n, k), a threshold grid several, each its own curve
    (pooled, points of one rate and another a0 gave a slope of +-inf).

    Returns
    -------
    list of dict
        One row per rate of the campaign (ascending): ``rate``, ``rhat_pb``, ``v_over_r``
        (median, min, max over the groups of vhat/rhat_PB at that rate) and, from the second
        rate on, ``slope`` (median, min, max over the groups of the local slope between this
        rate and the one below), ``n_groups``.
    """
    d = _vr_points(df, alpha)
    rates = np.sort(d["rate"].unique())
    slopes = {}
    curve = [a for a in SCENE_AXES if a != "rate" and a in d.columns]
    for _, g in d.groupby(curve, dropna=False):
        g = g.sort_values("rate")
        r = g["rate"].to_numpy(dtype=float)
        lr, lv = np.log(g["rhat_pb"].to_numpy(dtype=float)), np.log(g["vhat"].to_numpy(dtype=float))
        for i in range(1, r.size):
            slopes.setdefault(float(r[i]), []).append(float((lv[i] - lv[i - 1])
                                                           / (lr[i] - lr[i - 1])))
    out = []
    for rate in rates:
        g = d[d["rate"] == rate]
        ratio = (g["vhat"] / g["rhat_pb"]).to_numpy(dtype=float)
        row = {"rate": float(rate), "rhat_pb": float(g["rhat_pb"].iloc[0]),
               "v_over_r_median": float(np.median(ratio)), "v_over_r_min": float(ratio.min()),
               "v_over_r_max": float(ratio.max()), "n_groups": int(len(g))}
        s = slopes.get(float(rate))
        row.update(slope_median=float(np.median(s)) if s else math.nan,
                   slope_min=float(np.min(s)) if s else math.nan,
                   slope_max=float(np.max(s)) if s else math.nan)
        out.append(row)
    return out


def alpha_per_k(df: pd.DataFrame) -> list[dict]:
    """:func:`best_alpha` of each k of the v-r campaign alone (the paper: alpha ~ pi/9
    "independently on the ratio rubbery to glassy modulus k"). One dict per k: ``k``,
    ``alpha_best``, ``alpha_best_over_paper``, ``rms_log_error_best``,
    ``rms_log_error_paper_alpha``, ``n_points``."""
    d = _vr_points(df, units.ALPHA_PB)
    out = []
    for k in sorted(d["k"].unique()):
        sub = df[(df["k"] == k) & (df["material"] == "mpl")]
        try:
            a = best_alpha(sub)
        except InputError:
            continue
        out.append({"k": float(k), "alpha_best": a["alpha_best"],
                    "alpha_best_over_paper": a["alpha_best_over_paper"],
                    "rms_log_error_best": a["rms_log_error_best"],
                    "rms_log_error_paper_alpha": a["rms_log_error_paper_alpha"],
                    "n_points": int((d["k"] == k).sum())})
    return out


def bem_power_law(df: pd.DataFrame, k: float = 0.1, lo: float = 0.25, hi: float = 0.75,
                  alpha: float = units.ALPHA_PB, n_boot: int = N_BOOT,
                  seed: int = 0) -> list[dict]:
    r"""``Gamma_eff = beta vhat^m`` fitted to the BEM points of each n at ``k`` (the paper's
    Fig. PB_BEM inset, there fitted to the PB curve; here to our runs).

    The points are the finished MPL scenes at ``k`` whose ``Gamma_eff = P_po/1.5`` lies in
    the intermediate range ``[(1/k)^lo, (1/k)^hi]`` (the range :func:`pb_power_law` fits the PB
    curve over); least squares in log-log.

    Returns
    -------
    list of dict
        Per n: ``n``, ``beta``, ``m`` (+ ``_ci``, bootstrap), ``n_points``, ``vhat_range``;
        an n with fewer than 3 points in the range gives NaN.
    """
    d = _vr_points(df, alpha)
    d = d[np.isclose(d["k"].to_numpy(dtype=float), k)]
    g_lo, g_hi = (1.0 / k) ** lo, (1.0 / k) ** hi
    out = []
    for n in sorted(d["n"].unique()):
        g = d[(d["n"] == n) & (d["gamma_eff"] >= g_lo) & (d["gamma_eff"] <= g_hi)]
        row = {"n": float(n), "k": float(k), "n_points": int(len(g))}
        try:
            f = power_law_fit(g["vhat"], g["gamma_eff"], n_boot=n_boot, seed=seed)
            row.update(beta=f["prefactor"], m=f["exponent"], beta_ci=f["prefactor_ci"],
                       m_ci=f["exponent_ci"],
                       vhat_range=[float(g["vhat"].min()), float(g["vhat"].max())])
        except InputError:
            row.update(beta=math.nan, m=math.nan, beta_ci=None, m_ci=None, vhat_range=None)
        out.append(row)
    return out


#: the models whose rows are "the BEM" of a comparison with the Persson-Brener theory (the
#: elastic branch is the BEM's own k = 1 limit)
BEM_MODELS = ("bem", "elastic")


def bem_rows(df: pd.DataFrame, what: str = "the v-r fit") -> pd.DataFrame:
    """The rows of ``df`` that the BEM answered (``model_used``; every row of a file written
    before the column), an InputError (one line) if there are none. The crack-front model
    *is* the Persson-Brener law: its rows in a comparison with PB were circular ("within 15 %:
    100 %" on a file of crack-front and pb rows), and mixed into one power law."""
    if "model_used" not in df:
        return df
    used = df["model_used"].fillna("").astype(str)
    keep = used.isin(BEM_MODELS) | (used == "")
    if not keep.any():
        counts = ", ".join(f"{n} {m}" for m, n in used.value_counts().items())
        raise InputError(f"results: no BEM rows for {what} ({counts}): it compares the BEM's "
                         f"crack speed with Persson-Brener's; run the scenes with model bem")
    return df[keep]


def vr_analysis(df: pd.DataFrame, saturation_fraction: float = SATURATION_FRACTION,
                n_boot: int = N_BOOT, seed: int = 0,
                paper_fit: tuple[float, float] | None = None) -> dict:
    """Everything ``fit.json`` of the v-r campaign holds, from its runs table.

    Returns
    -------
    dict
        ``prefactor``, ``exponent``, ``prefactor_ci``, ``exponent_ci``, ``n_points`` (all
        MPL points), ``unsaturated`` (the same for P_po < fraction * 1.5/k),
        ``pb_share_within_15pct`` (Gamma_PB at the measured vhat), ``pb_vs_bem`` (both ways
        of :func:`pb_comparison` with this fit, plus ``predicted_paper_fit`` if ``paper_fit``
        (A, B) is given), ``alpha_best`` (:func:`best_alpha`) and its details, ``scenes``,
        ``failed``; beside them ``paper_range`` (the fit over the paper's rate grid,
        :func:`vr_paper_range`), ``local_slope`` (:func:`vr_local_slope`), ``alpha_per_k``
        (:func:`alpha_per_k`) and ``bem_power_law`` (beta, m of the BEM points,
        :func:`bem_power_law`). Only the BEM's rows count (:func:`bem_rows`; ``other_models``
        says how many others the file held).
    """
    others = int(len(df) - len(bem_rows(df)))
    df = bem_rows(df)
    fits = vr_fit(df, saturation_fraction, n_boot=n_boot, seed=seed)
    a = fits["all"]
    _, comp = pb_comparison(df, a["prefactor"], a["exponent"])
    if paper_fit is not None:
        _, comp_p = pb_comparison(df, *paper_fit)
        comp["predicted_paper_fit"] = comp_p["predicted"]
    alpha = best_alpha(df)
    return {
        "paper_range": vr_paper_range(df, n_boot=n_boot, seed=seed),
        "local_slope": vr_local_slope(df),
        "alpha_per_k": alpha_per_k(df),
        "bem_power_law": bem_power_law(df, n_boot=n_boot, seed=seed),
        "prefactor": a["prefactor"], "exponent": a["exponent"],
        "prefactor_ci": a["prefactor_ci"], "exponent_ci": a["exponent_ci"],
        "n_points": a["n_points"], "rms_log_residual": a["rms_log_residual"],
        "unsaturated": fits["unsaturated"], "saturation_fraction": saturation_fraction,
        "rhat_pb_definition": "rhat_PB = rate * h0 = r tau0 / d_ref (sweep.units.rhat_pb)",
        "pb_share_within_15pct": comp["measured"]["share_within_15pct"],
        "pb_median_error": comp["measured"]["median_abs_error"],
        "pb_vs_bem": comp,
        "alpha_best": alpha["alpha_best"], "alpha": alpha,
        "scenes": int(len(df)), "failed": int((df["status"] != "ok").sum()),
        "other_models": others,
    }


# --------------------------------------------------------------------------------------------
# power-law descriptions of the PB curve (Fig. PB_BEM inset, Appendix B Fig. B1)
# --------------------------------------------------------------------------------------------
def pb_power_law(n: float, k: float, lo: float = 0.25, hi: float = 0.75,
                 num: int = 200) -> dict:
    r"""``Gamma_eff = beta vhat^m`` fitted to the PB curve in its intermediate range.

    The intermediate range is where ``Gamma_eff`` lies between ``(1/k)^lo`` and
    ``(1/k)^hi`` (geometrically between 1 and the plateau 1/k); ``num`` log-spaced speeds
    there are fitted by least squares in log-log.

    Returns
    -------
    dict
        ``beta``, ``m``, ``vhat_range`` [lo, hi], ``max_rel_error`` of the power law over
        that range.
    """
    g_lo, g_hi = (1.0 / k) ** lo, (1.0 / k) ** hi

    def v_at(g):
        return brentq(lambda lv: math.log(pb_gamma_eff(n, k, math.exp(lv))) - math.log(g),
                      -40.0, 60.0, xtol=1e-12)

    v = np.exp(np.linspace(v_at(g_lo), v_at(g_hi), num))
    g = np.asarray(pb_gamma_eff(n, k, v))
    fit = power_law_fit(v, g, n_boot=0)
    model = fit["prefactor"] * v ** fit["exponent"]
    return {"beta": fit["prefactor"], "m": fit["exponent"],
            "vhat_range": [float(v[0]), float(v[-1])],
            "max_rel_error": float(np.max(np.abs(model / g - 1)))}


def pb_regimes(n: float, k: float, v_linear=(1e-4, 1e-2), v_power=(1e1, 1e3),
               num: int = 60) -> dict:
    r"""The two power-law regimes of ``Gamma_eff - 1`` (the paper's Appendix B, Fig. B1).

    ``Gamma_eff - 1 ~ q1 vhat`` for slow cracks (q1 fitted with the exponent fixed to 1 over
    ``v_linear``; its limit is ``(1-k) pi n``) and ``Gamma_eff - 1 ~ q2 vhat^m2`` over
    ``v_power`` (both fits least squares in log space on ``num`` log-spaced speeds).

    Returns
    -------
    dict
        ``q1``, ``q2``, ``m2``, ``q1_limit`` ((1-k) pi n), the ranges.
    """
    v1 = np.logspace(math.log10(v_linear[0]), math.log10(v_linear[1]), num)
    g1 = np.asarray(pb_gamma_eff(n, k, v1)) - 1.0
    q1 = float(np.exp(np.mean(np.log(g1 / v1))))
    v2 = np.logspace(math.log10(v_power[0]), math.log10(v_power[1]), num)
    g2 = np.asarray(pb_gamma_eff(n, k, v2)) - 1.0
    fit = power_law_fit(v2, g2, n_boot=0)
    return {"q1": q1, "q1_limit": (1.0 - k) * math.pi * n, "q2": fit["prefactor"],
            "m2": fit["exponent"], "v_linear": list(v_linear), "v_power": list(v_power)}
