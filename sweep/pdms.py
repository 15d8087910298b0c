r"""The paper's PDMS experiment in SI units (sections "Experimental adhesion tests" and
"Discussion"): predicted pull-off force versus unloading speed, the Gent-Schultz comparison
and the discussion's estimates, recomputed with this project's models.

``python -m sweep.pdms --out results/pdms`` (``make pdms``) writes ``pdms.json``, ``pdms.png``
and ``REPORT.md``. The case (:data:`PDMS_CASE`): glass lens R = 5.19 mm on Sylgard 184 with the
paper's MPL constants (E0 = 1.458 MPa, Einf = 3089 MPa, n = 0.2207, tau0 = 0.01876 s, nu = 0.5),
dg = 152.3 mJ/m^2, h0 = 30.8 nm, preload 1.5 mN after full relaxation, unloading speeds
1 .. 1e4 um/s. These are the paper's fitted INPUTS (no DMA data ship with the project; with a
master curve, ``sweep fit-dma`` gives the constants to put here).

Models (all in :mod:`sweep.crack_front` / :mod:`sweep.models`):

* ``crack_pb`` -- crack-front model, Gamma(v) = Persson-Brener of the MPL spectrum (linear
  viscoelasticity, the analogue of the paper's (P_po)_lin);
* ``crack_gs`` -- crack-front model, Gamma(v) = dg (1 + (v/v0)^xi) with the paper's fit of the
  experiments, v0 = 213.5 um/s, xi = 0.4154 (the analogue of the paper's green dashed line);
* ``pb_estimate`` -- the paper's closed-form chain: crack speed from its v-r fit
  vhat = 2.887 rhat^1.171 and P = 1.5 Gamma_PB(vhat), with rhat = r tau0/d_ref (docs/design.md section 2);
* ``pb_estimate_l0`` -- the same with rhat = r tau0/l0, the convention the paper uses in its
  PDMS discussion (it turns vhat = 1e9 into 31.4 m/s).

The BEM is not run: at mu = 103 the process zone l0 = 30 nm is 1.6e-4 a_ref, beyond the
uniform mesh (the Scene refuses mu > 20).
"""
from __future__ import annotations

import argparse
import json
import math
import os
import time
from pathlib import Path

import numpy as np
from scipy.optimize import brentq

from . import units
from .crack_front import GentSchultzLaw, pb_law_for_scene, unload
from .si import SIScene
from .theory import A_PULL_OFF_FORCE, gent_schultz, paper_v_vs_r_fit, pb_gamma_eff

#: The PDMS case of the paper (SI). ``threshold_collapse`` is the paper's BEM collapse fit
#: P_po = 0.3 a0t^2.7 (its Fig. Threshold), used for the discussion's threshold radius.
PDMS_CASE = {
    "R": 5.19e-3, "E0": 1.458e6, "Einf": 3.089e9, "nu": 0.5, "n": 0.2207, "tau0": 0.01876,
    "dg": 0.1523, "h0": 30.8e-9, "preload": 1.5e-3,
    "speeds_um_s": {"log10": [0.0, 4.0, 17]},
    "gent_schultz": {"v0_um_s": 213.5, "xi": 0.4154},
    "gs_over_linear": {"v1_um_s": 1.0e4, "exponent": 0.5},
    "threshold_collapse": {"prefactor": 0.3, "exponent": 2.7},
    "full_amplification_fraction": 0.9,
}


def _speeds(spec) -> np.ndarray:
    a, b, num = spec["log10"]
    return np.logspace(a, b, int(num))


def pdms_scene(speed_m_s: float, case=PDMS_CASE) -> SIScene:
    return SIScene(R=case["R"], E0=case["E0"], Einf=case["Einf"], nu=case["nu"], n=case["n"],
                   tau0=case["tau0"], dg=case["dg"], h0=case["h0"], preload=case["preload"],
                   speed=speed_m_s)


def compute(case=PDMS_CASE) -> dict:
    """Every number of the PDMS report (SI unless the key says otherwise)."""
    t0 = time.perf_counter()
    speeds_um = _speeds(case["speeds_um_s"])
    si0 = pdms_scene(1e-6, case)
    sc = si0.scale
    tau0, k, n, mu = si0.tau0, si0.k, si0.n, si0.mu
    d0 = si0.dimensionless()
    a0 = d0["a0"]
    law_pb = pb_law_for_scene(n, k, mu)
    gs = case["gent_schultz"]
    v0_hat = float(sc.crack_speed_hat(gs["v0_um_s"] * 1e-6, tau0))
    law_gs = GentSchultzLaw(v0_hat, gs["xi"])
    l0_hat = units.l0_hat(mu)
    out_models = {}
    for name, law in (("crack_pb", law_pb), ("crack_gs", law_gs)):
        rows = [unload(law, rate=pdms_scene(v * 1e-6, case).rate, mu=mu, a0=a0) for v in speeds_um]
        out_models[name] = {
            "pull_off_mN": [float(sc.load_physical(r.pull_off)) * 1e3 for r in rows],
            "crack_speed_um_s": [float(sc.crack_speed_physical(r.crack_speed, tau0)) * 1e6
                                 for r in rows],
            "gamma_pulloff": [r.gamma_pulloff for r in rows],
            "status": [r.status for r in rows],
        }
    rates = np.array([pdms_scene(v * 1e-6, case).rate for v in speeds_um])
    # the paper's closed-form chain with the two rhat conventions
    for name, rhat in (("pb_estimate", units.rhat_pb(rates, mu)),
                       ("pb_estimate_l0", speeds_um * 1e-6 * tau0 / sc.l0)):
        vhat = paper_v_vs_r_fit(rhat)
        g = pb_gamma_eff(n, k, vhat)
        out_models[name] = {
            "pull_off_mN": list(1.5 * g * sc.load_ref * 1e3),
            "crack_speed_um_s": list(vhat * sc.l0 / tau0 * 1e6),
            "gamma_pulloff": list(g),
            "status": ["ok"] * speeds_um.size,
        }
    # Gent-Schultz over the linear (PB) effective surface energy, against crack speed
    v_um = np.logspace(0.0, 4.0, 41)
    g_lin = pb_gamma_eff(n, k, v_um * 1e-6 * tau0 / sc.l0)
    g_gs = gent_schultz(v_um, gs["v0_um_s"], gs["xi"])
    v1 = case["gs_over_linear"]
    paper_ratio = 1.0 + (v_um / v1["v1_um_s"]) ** v1["exponent"]
    ratio = g_gs / g_lin
    # the same ratio along the unloading speeds, from the two crack-front pull-offs
    # (P = 1.5 pi R dg_eff), against the PB crack-front's crack speed at pull-off
    p_gs = np.array(out_models["crack_gs"]["pull_off_mN"])
    p_lin = np.array(out_models["crack_pb"]["pull_off_mN"])
    v_cf = np.array(out_models["crack_pb"]["crack_speed_um_s"])
    paper_cf = 1.0 + (v_cf / v1["v1_um_s"]) ** v1["exponent"]
    # threshold radius for the full amplification 1.5/k
    col = case["threshold_collapse"]
    a0t_hat = (1.5 / k / col["prefactor"]) ** (1.0 / col["exponent"])
    a0t_cf_hat = A_PULL_OFF_FORCE * k ** (-1.0 / 3.0)      # crack-front, pinned glassy limit
    # speed for the full amplification (fraction f of 1/k)
    f = case["full_amplification_fraction"]
    vhat_full = math.exp(brentq(lambda x: float(pb_gamma_eff(n, k, math.exp(x))) * k - f,
                                math.log(1e-3), math.log(1e24), xtol=1e-10))
    rhat_full = (vhat_full / 2.887) ** (1.0 / 1.171)
    speed_full_l0 = rhat_full * sc.l0 / tau0                 # paper's convention r tau0/l0
    speed_full_dref = rhat_full * sc.d_ref / tau0            # DESIGN's r tau0/d_ref
    # the crack-front model's own answer: unloading speed for f * 1.5/k with a0 = 2 a0t_cf
    a_big = 2.0 * a0t_cf_hat

    def short(log_r):
        return unload(law_pb, rate=10.0**log_r, mu=mu, a0=a_big).pull_off * k / 1.5 - f

    lo, hi = 0.0, 23.0       # beyond ~1e23 the PB table's speed cap is reached
    cf_ok = short(lo) < 0 < short(hi)
    log_rate_full = brentq(short, lo, hi, xtol=1e-4) if cf_ok else math.nan
    speed_full_cf = float(sc.rate_physical(10.0**log_rate_full, tau0)) if cf_ok else math.nan
    return {
        "case": {**{k_: v for k_, v in case.items() if not isinstance(v, dict)},
                 **{k_: v for k_, v in case.items() if isinstance(v, dict)}},
        "mu": mu, "k": k, "l0_nm": sc.l0 * 1e9, "a_ref_mm": sc.a_ref * 1e3,
        "d_ref_um": sc.d_ref * 1e6, "l0_over_a_ref": l0_hat,
        "a0_preload_mm": a0 * sc.a_ref * 1e3, "a0_preload_hat": a0,
        "jkr_pull_off_mN": 1.5 * sc.load_ref * 1e3,
        "speeds_um_s": list(speeds_um), "rate_hat": list(rates),
        "pull_off_mN": {m: d["pull_off_mN"] for m, d in out_models.items()},
        "models": out_models,
        "bem": "not run: mu = 103 is outside the BEM's reach (Scene mu <= 20; l0 = 1.6e-4 a_ref)",
        "gs_over_linear": {
            "crack_speed_um_s": list(v_um), "gamma_lin": list(g_lin), "gamma_gs": list(g_gs),
            "ratio": list(ratio), "paper_fit": list(paper_ratio),
            "max_rel_dev_from_paper_fit": float(np.max(np.abs(ratio / paper_ratio - 1.0))),
            "ratio_at_v1": float(gent_schultz(v1["v1_um_s"], gs["v0_um_s"], gs["xi"])
                                 / pb_gamma_eff(n, k, v1["v1_um_s"] * 1e-6 * tau0 / sc.l0)),
            "pull_off_ratio_crack_front": list(p_gs / p_lin),
            "pull_off_ratio_crack_speed_um_s": list(v_cf),
            "pull_off_ratio_paper_fit": list(paper_cf),
        },
        "a0t_hat": a0t_hat, "a0t_mm": a0t_hat * sc.a_ref * 1e3,
        "a0t_crack_front_hat": a0t_cf_hat, "a0t_crack_front_mm": a0t_cf_hat * sc.a_ref * 1e3,
        "full_amplification_fraction": f,
        "vhat_full_amplification": vhat_full,
        "speed_full_amplification_m_s": speed_full_l0,
        "speed_full_amplification_dref_m_s": speed_full_dref,
        "crack_speed_full_amplification_m_s": vhat_full * sc.l0 / tau0,
        "speed_full_amplification_crack_front_m_s": speed_full_cf,
        "crack_front_a0_for_full_amplification_hat": a_big,
        "wall_s": time.perf_counter() - t0,
    }


def plot(res: dict, out) -> Path:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import matplotlib.ticker  # noqa: F401 - used as matplotlib.ticker

    v = np.array(res["speeds_um_s"])
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(12, 4.8))
    styles = {"crack_pb": ("k-", "crack front, PB Gamma(v) (linear)"),
              "crack_gs": ("g--", "crack front, Gent-Schultz fit"),
              "pb_estimate": ("b:", "PB estimate, rhat = r tau0/d_ref"),
              "pb_estimate_l0": ("c-.", "PB estimate, rhat = r tau0/l0")}
    for name, (st, label) in styles.items():
        ax1.semilogx(v, res["pull_off_mN"][name], st, marker="o", ms=3, label=label)
    ax1.axhline(res["jkr_pull_off_mN"], color="0.5", lw=0.8, label="relaxed JKR 1.5 pi dg R")
    ax1.set_xlabel("unloading speed r [um/s]")
    ax1.set_ylabel("pull-off force [mN]")
    ax1.set_title(f"PDMS, preload 1.5 mN, mu = {res['mu']:.1f}, l0 = {res['l0_nm']:.1f} nm")
    ax1.legend(fontsize=8)
    ax1.grid(True, which="both", alpha=0.3)
    g = res["gs_over_linear"]
    vc = np.array(g["crack_speed_um_s"])
    ax2.loglog(vc, g["gamma_lin"], "k-", label="(dg_eff)_lin = Gamma_PB(v)")
    ax2.loglog(vc, g["gamma_gs"], "g--", label="(dg_eff)_GS = 1 + (v/v0)^xi")
    ax2.set_xlabel("crack speed v [um/s]")
    ax2.set_ylabel("dg_eff / dg")
    ax2.yaxis.set_major_formatter(matplotlib.ticker.ScalarFormatter())
    ax2.yaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())
    ax2.set_yticks([1, 1.5, 2, 3, 4, 5, 6])
    ax2.grid(True, which="both", alpha=0.3)
    ax3 = ax2.twinx()
    ax3.semilogx(vc, g["ratio"], "m-", label="ratio GS / lin")
    ax3.semilogx(vc, g["paper_fit"], "c--", label="paper: 1 + (v/v1)^(1/2)")
    ax3.semilogx(g["pull_off_ratio_crack_speed_um_s"], g["pull_off_ratio_crack_front"], "ms",
                 ms=4, label="(P_po)_GS / (P_po)_lin, crack front")
    ax3.set_ylabel("ratio")
    h1, l1 = ax2.get_legend_handles_labels()
    h2, l2 = ax3.get_legend_handles_labels()
    ax2.legend(h1 + h2, l1 + l2, fontsize=8, loc="upper left")
    fig.tight_layout()
    fig.savefig(out, dpi=110)
    plt.close(fig)
    return Path(out)


def _paper_values():
    """The paper's printed numbers (tests/data/paper_values.yaml), for the comparison column."""
    import yaml

    p = Path(__file__).resolve().parent.parent / "tests" / "data" / "paper_values.yaml"
    return yaml.safe_load(p.read_text())["pdms_experiment"] if p.is_file() else {}


def report(res: dict, out) -> Path:
    pv = _paper_values()
    speeds = res["speeds_um_s"]
    pick = [i for i, s in enumerate(speeds) if any(math.isclose(s, x) for x in (1, 10, 100, 1e3, 1e4))]
    L = ["# PDMS: pull-off force vs unloading speed (generated by `make pdms`)", "",
         "Glass lens on Sylgard 184 with the paper's constants (sweep/pdms.py `PDMS_CASE`). "
         "Paper values in the last column are for comparison only (tests/data/paper_values.yaml).",
         "", "| quantity | this project | paper |", "| --- | --- | --- |",
         f"| Tabor parameter mu | {res['mu']:.2f} | about 103 (h0 = {pv.get('h0_fit_nm')} nm) |",
         f"| l0 [nm] | {res['l0_nm']:.2f} | {pv.get('l0_nm')} |",
         f"| k = E0/Einf | {res['k']:.4g} | {pv.get('k')} |",
         f"| relaxed JKR pull-off [mN] | {res['jkr_pull_off_mN']:.4f} | 3.725 (1.5 pi dg R) |",
         f"| a0 at 1.5 mN preload [mm] | {res['a0_preload_mm']:.4f} ({res['a0_preload_hat']:.3f} a_ref) | -- |",
         f"| threshold radius a0t, paper's collapse with our k [a_ref / mm] | "
         f"{res['a0t_hat']:.2f} / {res['a0t_mm']:.2f} | "
         f"{pv.get('threshold_radius_estimate', {}).get('a0t_hat')} / "
         f"{pv.get('threshold_radius_estimate', {}).get('a0t_mm')} |",
         f"| threshold radius, crack-front model 1.040 k^(-1/3) [a_ref / mm] | "
         f"{res['a0t_crack_front_hat']:.2f} / {res['a0t_crack_front_mm']:.2f} | -- |",
         f"| vhat where Gamma_PB = {res['full_amplification_fraction']:g}/k | "
         f"{res['vhat_full_amplification']:.3g} | about 1e9 (read off Fig. PB_BEM) |",
         f"| unloading speed for it, v-r fit with r tau0/l0 [m/s] | "
         f"{res['speed_full_amplification_m_s']:.3g} | "
         f"{pv.get('max_amplification_rate_estimate', {}).get('r_m_s')} |",
         f"| same, v-r fit with r tau0/d_ref [m/s] | {res['speed_full_amplification_dref_m_s']:.3g} | -- |",
         f"| same, crack-front model (a0 = {res['crack_front_a0_for_full_amplification_hat']:.1f} a_ref) [m/s] | "
         f"{res['speed_full_amplification_crack_front_m_s']:.3g} | -- |",
         f"| GS/lin ratio at v1 = 1e4 um/s | {res['gs_over_linear']['ratio_at_v1']:.3f} | 2 (1 + (v/v1)^(1/2)) |",
         f"| max relative deviation of GS/lin from 1 + (v/v1)^(1/2), v = 1..1e4 um/s | "
         f"{res['gs_over_linear']['max_rel_dev_from_paper_fit']:.3f} | -- |",
         f"| (P_po)_GS/(P_po)_lin of the crack-front runs at r = 1e4 um/s (crack speed "
         f"{res['gs_over_linear']['pull_off_ratio_crack_speed_um_s'][-1]:.3g} um/s) | "
         f"{res['gs_over_linear']['pull_off_ratio_crack_front'][-1]:.3f} | -- |",
         "", "## Pull-off force [mN]", "",
         "| r [um/s] | crack front, PB | crack front, GS | PB estimate (d_ref) | PB estimate (l0) | crack speed, PB [um/s] |",
         "| --- | --- | --- | --- | --- | --- |"]
    for i in pick:
        p = res["pull_off_mN"]
        L.append(f"| {speeds[i]:g} | {p['crack_pb'][i]:.3f} | {p['crack_gs'][i]:.3f} | "
                 f"{p['pb_estimate'][i]:.3f} | {p['pb_estimate_l0'][i]:.3f} | "
                 f"{res['models']['crack_pb']['crack_speed_um_s'][i]:.3g} |")
    L += ["", "![pull-off and effective surface energy](pdms.png)", "",
          "## Notes", "",
          "* BEM: " + res["bem"] + ".",
          "* The crack-front model's crack speed at pull-off is about 16-20 times the unloading "
          "speed (JKR geometry, da/d(delta) ~ R/a_ref / 1.4 at a = 1.04 a_ref), so with l0 = 30 nm "
          "even 1 um/s gives vhat ~ 10 and Gamma_PB ~ 1.8: the linear crack-front prediction does "
          "NOT approach the relaxed JKR 3.725 mN at 1 um/s.",
          "* The paper's v-r fit was made at mu = 3.24; transferred to mu = 103 the two readings of "
          "rhat_PB differ by the factor d_ref/l0 = "
          f"{res['d_ref_um'] * 1e3 / res['l0_nm']:.0f}, hence the two PB-estimate columns.",
          f"* Full amplification is defined here as Gamma_PB = {res['full_amplification_fraction']:g}/k; "
          "for n = 0.22 the approach to 1/k is slow (1/k - Gamma ~ vhat^(-n)).",
          f"* Wall time {res['wall_s']:.1f} s."]
    Path(out).write_text("\n".join(L) + "\n")
    return Path(out)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--out", default="results/pdms", help="output directory")
    args = ap.parse_args(argv)
    os.makedirs(args.out, exist_ok=True)
    res = compute()
    out = Path(args.out)
    tmp = out / "pdms.json.tmp"
    tmp.write_text(json.dumps(res, indent=1, default=float) + "\n")
    os.replace(tmp, out / "pdms.json")
    plot(res, out / "pdms.png")
    report(res, out / "REPORT.md")
    print(f"{out / 'pdms.json'}\n{out / 'pdms.png'}\n{out / 'REPORT.md'}")
    return 0


if __name__ == "__main__":  # pragma: no cover
    raise SystemExit(main())
