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
    "vr_fit",
    "pb_gamma_eff_scene",
    "pb_points",
    "pb_comparison",
    "best_alpha",
    "vr_analysis",
    "pb_power_law",
    "pb_regimes",
]

#: The paper's rule for the threshold radius: dP_po/da0 below this (section "Threshold ...").
THRESHOLD_SLOPE = 0.1
#: Default share of the saturation 1.5/k below which a point counts as unsaturated.
SATURATION_FRACTION = 0.9
#: Bootstrap resamples and confidence level of every interval.
N_BOOT = 2000
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
    with replacement (resamples whose ``x`` are all equal are skipped).

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
        None), ``n_points``, ``rms_log_residual`` (RMS of ``ln y - ln(A x^B)``).
    """
    x = np.asarray(x, dtype=float).ravel()
    y = np.asarray(y, dtype=float).ravel()
    if x.size != y.size:
        raise InputError(f"x and y must have equal lengths (got {x.size} and {y.size})")
    if x.size < 3 or np.unique(x).size < 2:
        raise InputError(
            f"a power-law fit needs at least 3 points with 2 distinct x (got {x.size})"
        )
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
    if n_boot > 0:
        rng = np.random.default_rng(seed)
        idx = rng.integers(0, x.size, size=(int(n_boot), x.size))
        bx, by = lx[idx], ly[idx]
        mx, my = bx.mean(axis=1), by.mean(axis=1)
        var = ((bx - mx[:, None]) ** 2).sum(axis=1)
        ok = var > 1e-14 * max(1.0, float(np.var(lx)) * x.size)
        b = ((bx - mx[:, None]) * (by - my[:, None])).sum(axis=1)[ok] / var[ok]
        a = np.exp(my[ok] - b * mx[ok])
        q = [50.0 * (1.0 - confidence), 50.0 * (1.0 + confidence)]
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
    points give NaN."""
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
            row.update(prefactor=math.nan, exponent=math.nan, prefactor_ci=None,
                       exponent_ci=None, n_points=0, prefactor_inner=math.nan,
                       exponent_inner=math.nan)
        out.append(row)
    return out


def threshold_analysis(df: pd.DataFrame, slope: float = THRESHOLD_SLOPE,
                       saturation_fraction: float = SATURATION_FRACTION,
                       n_boot: int = N_BOOT, seed: int = 0) -> dict:
    """Everything ``fit.json`` of the threshold campaign holds, from its runs table.

    Returns
    -------
    dict
        ``prefactor``, ``exponent``, ``prefactor_ci``, ``exponent_ci``, ``n_points``,
        ``rms_log_residual`` (chosen rule: :data:`SENSITIVITY_RULES` [0]), ``rule`` (text),
        ``prefactor_inner`` (+ ``_ci``, ``exponent_inner``: the same points with a0t the
        h = h0 radius), ``prefactor_no_pi`` (A for a0 in (R^2 dg/E0*)^(1/3), i.e.
        ``A pi^(-B/3)``), ``sensitivity`` (:func:`collapse_sensitivity`), ``table`` (rows
        of n, rate, a0t, P_at_a0t, ...), ``overshoots`` (groups whose spline peak exceeds
        the largest-a0 pull-off by more than 5 %), ``scenes``, ``failed``.
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
    over = table[table["overshoot"] > 0.05]
    return {
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
    return {"all": power_law_fit(d["rhat_pb"], d["vhat"], n_boot, seed),
            "unsaturated": power_law_fit(uns["rhat_pb"], uns["vhat"], n_boot, seed),
            "saturation_fraction": float(saturation_fraction)}


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
        ``failed``.
    """
    fits = vr_fit(df, saturation_fraction, n_boot=n_boot, seed=seed)
    a = fits["all"]
    _, comp = pb_comparison(df, a["prefactor"], a["exponent"])
    if paper_fit is not None:
        _, comp_p = pb_comparison(df, *paper_fit)
        comp["predicted_paper_fit"] = comp_p["predicted"]
    alpha = best_alpha(df)
    return {
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
