r"""The paper's figures, redrawn from this project's runs and theory (matplotlib, ``plot`` extra).

Each function takes tables/dicts made by :mod:`sweep.analysis.fits` (or a runs table of
:func:`sweep.load`) and writes one PNG; none computes a fit itself. Symbols follow the paper:
``P_po`` (pull-off, units pi dg R), ``a0`` (initial contact radius, a_ref, the max-tension
radius), ``r-hat`` (rate r tau0/h0), ``r-hat_PB`` (r tau0/d_ref), ``v-hat`` (v tau0/l0),
``Gamma_eff`` (P_po/1.5). Markers as in the paper: n = 0.4, 0.6, 0.8, 1.6 are triangle, star,
diamond, square; the SLS blue circles; k = 0.01, 0.05, 0.1 blue edge, black edge, no edge.
"""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pandas as pd
from scipy.interpolate import CubicSpline

from ..analysis.plots import pyplot as _pyplot
from ..materials import SLS, MPLRelaxation, MPLRetardation
from ..theory import jkr_load

__all__ = ["threshold_figure", "vr_figure", "pb_vs_bem_figure", "fig3_figure",
           "aconv_figure", "mplplot_figure", "pb_bem_figure", "b1_figure"]

MARKERS = {0.2: "o", 0.4: "^", 0.6: "*", 0.8: "D", 1.6: "s"}
K_EDGE = {0.01: "tab:blue", 0.05: "black", 0.1: "none"}
_COLORS = {0.2: "tab:gray", 0.4: "tab:red", 0.6: "tab:orange", 0.8: "tab:green",
           1.0: "tab:brown", 1.2: "tab:pink", 1.6: "tab:purple"}


def _marker(n):
    return MARKERS.get(round(float(n), 3), "o")


def _color(n):
    return _COLORS.get(round(float(n), 3), "black")


def _save(fig, out) -> Path:
    out = Path(out)
    out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(out, dpi=130, bbox_inches="tight")
    _pyplot().close(fig)
    return out


def _rate_label(rate):
    e = math.log10(rate)
    return f"$10^{{{e:.3g}}}$" if abs(e - round(e)) > 1e-6 else f"$10^{{{round(e)}}}$"


def _held(d: pd.DataFrame, *columns) -> str:
    """``k = 0.1, mu = 3.24``: the values of ``columns`` over the rows ``d`` (a range
    where one varies): a title says what the data hold, not the paper's campaign."""
    names = {"mu": r"$\mu$", "a0": r"$\hat a_0$"}
    parts = []
    for c in columns:
        v = d[c].dropna().unique() if c in d else []
        if len(v) == 1:
            parts.append(f"{names.get(c, c)} = {float(v[0]):g}")
        elif len(v) > 1:
            parts.append(f"{names.get(c, c)} = {float(min(v)):g}-{float(max(v)):g}")
    return ", ".join(parts)


def _rates(d: pd.DataFrame) -> str:
    """The rates of ``d``: ``every rate 10^0-10^6`` from its rows."""
    r = d["rate"].dropna()
    return (f"rate {_rate_label(r.min())}" if r.nunique() == 1 else
            f"rates {_rate_label(r.min())}-{_rate_label(r.max())}") if len(r) else "no rate"


def _spline_curve(ax, g, a0t, color, label, marker, **kw):
    """Markers of P_po(a0) and their spline: dotted below a0t, solid above (the paper's style)."""
    a, p = g["a0"].to_numpy(float), g["pull_off"].to_numpy(float)
    ax.plot(a, p, marker, color=color, ms=5, label=label, **kw)
    if a.size >= 4:
        s = CubicSpline(a, p, bc_type="natural")
        fine = np.linspace(a[0], a[-1], 400)
        cut = a0t if np.isfinite(a0t) else a[-1]
        ax.plot(fine[fine <= cut], s(fine[fine <= cut]), ":", color=color, lw=1)
        ax.plot(fine[fine >= cut], s(fine[fine >= cut]), "-", color=color, lw=1)
        if np.isfinite(a0t):
            ax.plot([a0t], [s(a0t)], "o", mfc="white", mec="black", ms=7, zorder=5)


def threshold_figure(runs: pd.DataFrame, fit: dict, out, reference_rate=10**0.5,
                     overshoot_n=1.6, paper=(0.3, 2.7)) -> Path:
    """The paper's Fig. Threshold, plus a panel showing the overshoot.

    (a) ``P_po`` vs ``a0`` at ``reference_rate`` for each n (spline dotted below ``a0t``,
    solid above, open circle at ``a0t``); (b) ``P_po(a0t)`` vs ``a0t`` with the fit, the
    paper's line and the saturation ``1.5/k`` (inset ``a0t`` vs rate); (c) ``P_po(a0)`` of
    ``n = overshoot_n`` at every rate (overshoot and the first-crossing rule).
    ``fit`` is :func:`sweep.analysis.fits.threshold_analysis` output; ``runs`` the runs table.
    """
    plt = _pyplot()
    ok = runs[runs["status"] == "ok"].sort_values("a0")
    table = pd.DataFrame(fit["table"])
    fig, axes = plt.subplots(2, 2, figsize=(14, 11))
    axes = axes.ravel()
    ax = axes[0]
    for n, g in ok[np.isclose(ok["rate"], reference_rate)].groupby("n"):
        row = table[np.isclose(table["n"], n) & np.isclose(table["rate"], reference_rate)]
        a0t = float(row["a0t"].iloc[0]) if len(row) else math.nan
        _spline_curve(ax, g, a0t, _color(n), f"n = {n:g}", _marker(n))
    ax.plot([], [], "o", mfc="white", mec="black", label=r"$\hat a_{0t}$ ($d\hat P_{po}/d\hat a_0 = 0.1$)")
    ax.set_xlabel(r"initial contact radius $\hat a_0$")
    ax.set_ylabel(r"pull-off force $\hat P_{po}$")
    ax.set_title(rf"(a) $\hat r = ${_rate_label(reference_rate)}, {_held(ok, 'k', 'mu')}")
    ax.legend(fontsize=8, loc="center right")

    ax = axes[1]
    sat = float(table["saturation"].iloc[0])
    k_val = float(table["k"].iloc[0])
    interior = table[table["status"] == "interior"]
    for n, g in interior.groupby("n"):
        inf = g[g["in_fit"]]
        ax.loglog(inf["a0t"], inf["P_at_a0t"], _marker(n), color=_color(n), ms=6,
                  label=f"n = {n:g}")
        rest = g[~g["in_fit"]]
        ax.loglog(rest["a0t"], rest["P_at_a0t"], _marker(n), mfc="none", mec=_color(n), ms=6)
    used = table[table["in_fit"]]
    x = np.linspace(used["a0t"].min(), used["a0t"].max(), 100)
    A, B = fit["prefactor"], fit["exponent"]
    ci = fit["exponent_ci"]
    ax.loglog(x, A * x**B, "k--",
              label=rf"fit $\hat P_{{po}} = {A:.3g}\,\hat a_{{0t}}^{{{B:.3g}}}$"
                    + (rf" (B 95 % CI {ci[0]:.2f}-{ci[1]:.2f})" if ci is not None else
                       f" (no interval: {fit['n_points']} points)"))
    xp = np.linspace(1.0, interior["a0t"].max() * 1.05, 100)
    ax.loglog(xp, paper[0] * xp ** paper[1], ":", color="gray",
              label=rf"paper $\hat P_{{po}} = {paper[0]}\,\hat a_{{0t}}^{{{paper[1]}}}$")
    ax.axhline(sat, color="tab:blue", lw=1, label=rf"saturation $1.5/k$ = {sat:g} (k = {k_val:g})")
    ax.set_ylim(1.0, sat * 1.6)
    _plain_log_ticks(ax, x=[1, 1.5, 2, 3, 4, 5, 6], y=[1, 2, 3, 5, 10, 15, 20])
    ax.set_xlabel(r"threshold contact radius $\hat a_{0t}$")
    ax.set_ylabel(r"pull-off force at the threshold $\hat P_{po}(\hat a_{0t})$")
    ax.set_title(rf"(b) collapse, {_rates(table)}; open: not fitted ($\geq$ "
                 rf"{fit['saturation_fraction']:g} x 1.5/k)", fontsize=10)
    ax.legend(fontsize=8, loc="lower right")

    ax = axes[2]
    for n, g in interior.groupby("n"):
        ax.semilogx(g["rate"], g["a0t"], _marker(n), color=_color(n), ms=6, ls="-", lw=0.8,
                    label=f"n = {n:g}")
    ax.set_xlabel(r"unloading rate $\hat r = r\tau_0/h_0$")
    ax.set_ylabel(r"threshold contact radius $\hat a_{0t}$")
    ax.set_title("(b, inset) threshold radius vs rate")
    ax.legend(fontsize=8)

    ax = axes[3]
    sel = ok[np.isclose(ok["n"], overshoot_n)]
    rates = sorted(sel["rate"].unique())
    cmap = plt.get_cmap("viridis")
    for i, rate in enumerate(rates):
        g = sel[np.isclose(sel["rate"], rate)]
        row = table[np.isclose(table["n"], overshoot_n) & np.isclose(table["rate"], rate)]
        a0t = float(row["a0t"].iloc[0]) if len(row) else math.nan
        _spline_curve(ax, g, a0t, cmap(i / max(1, len(rates) - 1)),
                      rf"$\hat r$ = {_rate_label(rate)}", _marker(overshoot_n))
    ax.axhline(sat, color="tab:blue", lw=1)
    ax.set_xlabel(r"initial contact radius $\hat a_0$")
    ax.set_ylabel(r"pull-off force $\hat P_{po}$")
    ax.set_title(rf"(c) n = {overshoot_n:g}, every rate: overshoot, first crossing taken")
    if rates:
        ax.legend(fontsize=7, ncol=2, loc="lower right")
    fig.tight_layout()
    return _save(fig, out)


def _plain_log_ticks(ax, x=None, y=None):
    """Plain-number ticks on log axes that span less than a decade or two."""
    from matplotlib.ticker import NullFormatter, ScalarFormatter  # optional dependency

    for axis, ticks in ((ax.xaxis, x), (ax.yaxis, y)):
        if ticks is not None:
            axis.set_major_formatter(ScalarFormatter())
            axis.set_minor_formatter(NullFormatter())
            axis.set_ticks(ticks)


def _k_edge(k):
    return K_EDGE.get(round(float(k), 4), "gray")


def _vr_scatter(ax, d, xcol, ycol):
    """Scatter with the paper's markers: shape by n, edge by k; SLS as blue circles."""
    for (mat, n, k), g in d.groupby(["material", "n", "k"]):
        if mat == "sls":
            ax.plot(g[xcol], g[ycol], "o", color="tab:blue", ms=6, mec="tab:blue",
                    label=f"SLS, k = {k:g}")
            continue
        edge = _k_edge(k)
        ax.plot(g[xcol], g[ycol], _marker(n), color=_color(n), ms=6,
                mec=_color(n) if edge == "none" else edge, mew=1.4 if edge != "none" else 0.5,
                label=f"n = {n:g}, k = {k:g}")


def vr_figure(points: pd.DataFrame, fit: dict, out, paper=(2.887, 1.171)) -> Path:
    """The inset of the paper's Fig. r_v: ``v-hat`` vs ``r-hat_PB`` (log-log), our two fits
    and the paper's. ``points``: :func:`sweep.analysis.fits.paper_variables` of the finished runs."""
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(8, 6))
    d = points[(points["vhat"] > 0)]
    _vr_scatter(ax, d, "rhat_pb", "vhat")
    x = np.logspace(np.log10(d["rhat_pb"].min()), np.log10(d["rhat_pb"].max()), 50)
    u = fit["unsaturated"]
    ax.loglog(x, fit["prefactor"] * x ** fit["exponent"], "k-", lw=1.5,
              label=rf"fit, all MPL: $\hat v = {fit['prefactor']:.3g}\,\hat r_{{PB}}^{{{fit['exponent']:.3f}}}$")
    ax.loglog(x, u["prefactor"] * x ** u["exponent"], "k--", lw=1.2,
              label=rf"fit, unsaturated: $\hat v = {u['prefactor']:.3g}\,\hat r_{{PB}}^{{{u['exponent']:.3f}}}$")
    ax.loglog(x, paper[0] * x ** paper[1], ":", color="tab:red", lw=1.5,
              label=rf"paper: $\hat v = {paper[0]}\,\hat r_{{PB}}^{{{paper[1]}}}$")
    ax.set_xlabel(r"unloading rate $\hat r_{PB} = r\tau_0/d_{ref} = \hat r\,\hat h_0$")
    ax.set_ylabel(r"crack speed at pull-off $\hat v = v\tau_0/l_0$")
    ax.set_title(rf"crack speed vs unloading rate ({_held(d, 'mu')}; edge: k = 0.01 blue, 0.05 "
                 rf"black, 0.1 none)", fontsize=9)
    ax.legend(fontsize=6.5, ncol=2)
    return _save(fig, out)


def pb_vs_bem_figure(points: pd.DataFrame, comp: dict, out) -> Path:
    """The paper's Fig. r_v main panel and the direct check: ``Gamma_eff`` of the BEM against
    PB at the crack speed predicted from the rate by the v-r fit (left) and at the measured
    crack speed (right), with the 1:1 and +-15 % lines. ``points``: the first value of
    :func:`sweep.analysis.fits.pb_comparison`, ``comp`` its second."""
    plt = _pyplot()
    fig, axes = plt.subplots(1, 2, figsize=(13, 5.8))
    for ax, col, way, title in (
            (axes[0], "gamma_pb_predicted", "predicted",
             rf"PB at $\hat v = {comp['prefactor']:.3g}\,\hat r_{{PB}}^{{{comp['exponent']:.3f}}}$ (fit)"),
            (axes[1], "gamma_pb_measured", "measured", r"PB at the measured $\hat v$")):
        _vr_scatter(ax, points, col, "gamma_eff")
        lo = 0.9 * min(points[col].min(), points["gamma_eff"].min())
        hi = 1.1 * max(points[col].max(), points["gamma_eff"].max())
        x = np.array([lo, hi])
        ax.loglog(x, x, "k-", lw=1, label="perfect match")
        ax.loglog(x, 1.15 * x, "k--", lw=0.8, label=r"$\pm$15 %")
        ax.loglog(x, x / 1.15, "k--", lw=0.8)
        c = comp[way]
        ax.set_title(f"{title}\nMPL scenes within 15 %: {100 * c['share_within_15pct']:.0f} % "
                     f"of {c['n_points']}, median error {100 * c['median_abs_error']:.1f} %",
                     fontsize=9)
        ticks = [t for t in (1, 1.5, 2, 3, 5, 10, 20, 30, 50, 100) if lo <= t <= hi]
        _plain_log_ticks(ax, x=ticks, y=ticks)
        ax.set_xlabel(r"$\hat\Gamma_{eff}$ Persson-Brener (eq. PBmodel2, $\alpha = \pi/9$)")
        ax.set_ylabel(r"$\hat\Gamma_{eff} = \hat P_{po}/1.5$ BEM")
    axes[0].legend(fontsize=6.5, ncol=2)
    fig.tight_layout()
    return _save(fig, out)


#: Fig. 3's panels: title, the rows a panel draws, the axis its curves differ in, their label
FIG3_PANELS = [
    ("(a) n = 0.8, $\\hat a_0$ = 3.61", lambda d: np.isclose(d.n, 0.8) & np.isclose(d.a0, 3.61),
     "rate", lambda v: rf"$\hat r$ = {_rate_label(v)}"),
    ("(b) $\\hat a_0$ = 3.61, $\\hat r = 10^{2.5}$",
     lambda d: np.isclose(d.a0, 3.61) & np.isclose(d.rate, 10**2.5), "n", lambda v: f"n = {v:g}"),
    ("(c) n = 1.6, $\\hat r = 10^{2.5}$",
     lambda d: np.isclose(d.n, 1.6) & np.isclose(d.rate, 10**2.5), "a0",
     lambda v: rf"$\hat a_0$ = {v:g}"),
]


def fig3_panels(ok: pd.DataFrame) -> list[int]:
    """How many of the rows ``ok`` each panel of Fig. 3 draws (a file without its scenes
    had drawn three empty panels and exited 0)."""
    return [int(sel(ok).sum()) for _, sel, _, _ in FIG3_PANELS]


def fig3_figure(runs: pd.DataFrame, trajectories: dict, out) -> Path:
    """The paper's Fig. 3: ``P(a)`` during unloading; panels (a) rates (n = 0.8, a0 = 3.61),
    (b) n (rate 10^2.5), (c) a0 (n = 1.6, rate 10^2.5); the JKR curve for reference.
    ``trajectories`` maps scene_id to the dict of :func:`sweep.load_trajectory`."""
    plt = _pyplot()
    fig, axes = plt.subplots(1, 3, figsize=(16, 5))
    panels = FIG3_PANELS
    ok = runs[runs["status"] == "ok"]
    a = np.linspace(0.05, 4.5, 300)
    for ax, (title, sel, key, lab) in zip(axes, panels):
        p_lo, p_hi = -2.0, 5.0
        for _, row in ok[sel(ok)].sort_values(key).iterrows():
            tr = trajectories.get(row["scene_id"])
            if tr is None:
                continue
            ax.plot(tr["a"], tr["P"], lw=1.3, label=f"{lab(row[key])}: $\\hat P_{{po}}$ = "
                                                     f"{row['pull_off']:.2f}")
            p_lo, p_hi = min(p_lo, np.min(tr["P"])), max(p_hi, np.max(tr["P"]))
        ax.plot(a, jkr_load(a), "k--", lw=0.8, label="JKR (relaxed)")
        ax.set_ylim(1.15 * p_lo, 1.1 * p_hi)
        ax.axhline(0, color="gray", lw=0.5)
        ax.set_xlabel(r"contact radius $\hat a$")
        ax.set_ylabel(r"load $\hat P$ (positive compressive)")
        ax.set_title(", ".join(t for t in (title, _held(ok[sel(ok)], "k", "mu")) if t),
                     fontsize=10)
        ax.set_xlim(0, 4.2)
        ax.legend(fontsize=7)
    fig.tight_layout()
    return _save(fig, out)


def aconv_figure(runs: pd.DataFrame, out) -> Path:
    """The paper's Fig. aconv: ``P_po`` vs ``r-hat`` (log x) for several ``a0``, n = 0.8."""
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(7, 5))
    ok = runs[runs["status"] == "ok"]
    several_n = ok["n"].nunique() > 1          # one line per (n, a0), not one zig-zag per a0
    for (n, a0), g in ok.groupby(["n", "a0"]):
        g = g.sort_values("rate")
        ax.semilogx(g["rate"], g["pull_off"], "D-", ms=5,
                    label=(f"n = {n:g}, " if several_n else "") + rf"$\hat a_0$ = {a0:g}")
    k = float(ok["k"].iloc[0])
    ax.axhline(1.5 / k, color="tab:blue", lw=1, ls="--", label=f"$1.5/k$ = {1.5 / k:g}")
    ax.set_xlabel(r"unloading rate $\hat r = r\tau_0/h_0$")
    ax.set_ylabel(r"pull-off force $\hat P_{po}$")
    ax.set_title(f"{_held(ok, 'n', 'k', 'mu')}, relaxed start")
    ax.legend(fontsize=8)
    return _save(fig, out)


def mplplot_figure(out, n_values=(0.2, 0.4, 0.6), k=0.1) -> Path:
    """The paper's Fig. MPLplot: (a) relaxation ``R(t)/E0`` of the MPL relaxation model
    (eq. Rt3), (b) creep ``C(t)/C0`` of the MPL retardation model (eq. Ctgen), against the
    SLS (dashed blue)."""
    plt = _pyplot()
    t = np.logspace(-4, 6, 300)
    fig, axes = plt.subplots(1, 2, figsize=(12, 4.8))
    sls = SLS.from_k(k)
    styles = ["-", "--", "-."]
    for i, n in enumerate(n_values):
        ls = styles[i % 3]
        axes[0].semilogx(t, MPLRelaxation.from_k(n, k).normalized_relaxation_modulus(t), "k",
                         ls=ls, label=f"MPL n = {n:g}")
        axes[1].semilogx(t, MPLRetardation.from_k(n, k).normalized_creep_compliance(t), "k",
                         ls=ls, label=f"MPL n = {n:g}")
    axes[0].semilogx(t, sls.normalized_relaxation_modulus(t), color="tab:blue", ls="--",
                     lw=2, label="SLS")
    axes[1].semilogx(t, sls.normalized_creep_compliance(t), color="tab:blue", ls="--", lw=2,
                     label="SLS")
    axes[0].set_ylabel(r"$\hat R = R(t)/E_0$ (MPL relaxation spectrum, eq. Rt3)")
    axes[1].set_ylabel(r"$\hat C = C(t)/C_0$ (MPL retardation spectrum, eq. Ctgen)")
    for ax, lab in zip(axes, "ab"):
        ax.set_xlabel(r"$\hat t = t/\tau_0$")
        ax.set_title(f"({lab}) k = E0/Einf = {k:g}")
        ax.legend(fontsize=8)
    fig.tight_layout()
    return _save(fig, out)


def pb_bem_figure(curves: dict, laws: dict, points: pd.DataFrame, out, k=0.1) -> Path:
    """The paper's Fig. PB_BEM: PB ``Gamma_eff(v-hat)`` lines (MPL n values and the SLS), the
    BEM markers (k = ``k``), the intermediate power laws ``beta v^m`` (dashed), and ``beta``,
    ``m`` vs n in an inset. ``curves`` maps a label (n or "sls") to (vhat, gamma);
    ``laws`` maps n to :func:`sweep.analysis.fits.pb_power_law` output."""
    plt = _pyplot()
    fig, (ax, side) = plt.subplots(1, 2, figsize=(13, 6), gridspec_kw={"width_ratios": [2.3, 1]})
    for key, (v, g) in curves.items():
        if key == "sls":
            ax.loglog(v, g, color="tab:blue", lw=1.5, label="PB, SLS")
        else:
            ax.loglog(v, g, color=_color(key), lw=1.2, label=f"PB, n = {key:g}")
    for n, law in laws.items():
        vv = np.logspace(*np.log10(law["vhat_range"]), 20)
        ax.loglog(vv, law["beta"] * vv ** law["m"], "--", color="tab:cyan", lw=1.5)
    ax.plot([], [], "--", color="tab:cyan", label=r"$\beta\hat v^m$ (intermediate range)")
    d = points[np.isclose(points["k"], k) & (points["vhat"] > 0)]
    for (mat, n), g in d.groupby(["material", "n"]):
        if mat == "sls":
            ax.plot(g["vhat"], g["gamma_eff"], "o", color="tab:blue", ms=6, label="BEM, SLS")
        else:
            ax.plot(g["vhat"], g["gamma_eff"], _marker(n), color=_color(n), ms=6, mec="black",
                    mew=0.5, label=f"BEM, n = {n:g}")
    ax.set_xlabel(r"crack speed $\hat v = v\tau_0/l_0$")
    ax.set_ylabel(r"$\hat\Gamma_{eff} = \Delta\gamma_{eff}/\Delta\gamma_0$ (BEM: $\hat P_{po}/1.5$)")
    ax.set_title(rf"Persson-Brener (lines, $\alpha = \pi/9$) and BEM (markers), k = {k:g}")
    ax.legend(fontsize=7, loc="lower right", ncol=2)
    ns = sorted(laws)
    side.plot(ns, [laws[n]["beta"] for n in ns], "ko-", ms=5, label=r"$\beta$")
    side.plot(ns, [laws[n]["m"] for n in ns], "rs--", ms=5, label="m")
    side.set_xlabel("material exponent n")
    side.set_ylabel(r"$\beta$, m of $\hat\Gamma_{eff} = \beta\hat v^m$")
    side.set_title("(the paper's inset)")
    side.legend()
    fig.tight_layout()
    return _save(fig, out)


def b1_figure(curves: dict, regimes: dict, out, k: float, paper_q1=(-0.0125, 3.136)) -> Path:
    """Appendix B, Fig. B1: ``Gamma_eff - 1`` vs ``v-hat`` with the two power laws, ``q1`` vs
    n against the paper's ``q1 = -0.0125 + 3.136 n`` and ``q2``, ``m2`` vs n.
    ``curves`` maps n to (vhat, gamma); ``regimes`` maps n to
    :func:`sweep.analysis.fits.pb_regimes` output."""
    plt = _pyplot()
    fig, axes = plt.subplots(1, 2, figsize=(13, 5.2))
    ax = axes[0]
    for n, (v, g) in curves.items():
        ax.loglog(v, g - 1.0, color=_color(n), lw=1.3, label=f"n = {n:g}")
        r = regimes[n]
        v1 = np.logspace(-4, 0, 10)
        ax.loglog(v1, r["q1"] * v1, ":", color="black", lw=1)
        v2 = np.logspace(np.log10(r["v_power"][0]), np.log10(r["v_power"][1]), 10)
        ax.loglog(v2, r["q2"] * v2 ** r["m2"], "--", color="black", lw=1)
    ax.plot([], [], "k:", label=r"$q_1\hat v$")
    ax.plot([], [], "k--", label=r"$q_2\hat v^{m_2}$")
    ax.set_xlabel(r"crack speed $\hat v$")
    ax.set_ylabel(r"$\hat\Gamma_{eff} - 1$")
    ax.set_title(f"Persson-Brener, MPL, k = {k:g}")
    ax.legend(fontsize=8)
    ax = axes[1]
    ns = np.array(sorted(regimes))
    ax.plot(ns, [regimes[n]["q1"] for n in ns], "ko", label=r"$q_1$ (fit, $\hat v \leq 10^{-2}$)")
    ax.plot(ns, paper_q1[0] + paper_q1[1] * ns, "r-", lw=1,
            label=rf"paper $q_1 = {paper_q1[0]} + {paper_q1[1]}\,n$")
    ax.plot(ns, [regimes[n]["q2"] for n in ns], "bs--", label=r"$q_2$")
    ax.plot(ns, [regimes[n]["m2"] for n in ns], "g^--", label=r"$m_2$")
    ax.set_xlabel("material exponent n")
    ax.set_ylabel(r"$q_1$, $q_2$, $m_2$")
    ax.set_title(r"coefficients of the two regimes")
    ax.legend(fontsize=8)
    fig.tight_layout()
    return _save(fig, out)
