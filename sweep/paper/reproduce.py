r"""Reproduction of the paper: turn this project's runs into fit files, figures and a report.

The Makefile targets call this module after ``sweep run`` (``sweep reproduce ...``, or
``python -m sweep.paper.reproduce ...``). Like :mod:`sweep.cli`, of which it is the
``reproduce`` group, it imports its commands' machinery (fits, figures, the results store) in
their bodies, so that ``sweep reproduce --help`` starts at once:

=================  =========================================================================
command            writes (in OUTDIR)
=================  =========================================================================
``threshold RUNS``  ``fit.json`` (:func:`sweep.analysis.fits.threshold_analysis`), ``threshold.png``
``vr RUNS``         ``fit.json`` (:func:`sweep.analysis.fits.vr_analysis`), ``v_vs_r.png``,
                    ``pb_vs_bem.png``
``fig3 RUNS``       ``fig3.png`` (trajectories P(a))
``aconv RUNS``      ``aconv.png``, ``aconv.json`` (the pull-offs plotted)
``theory``          ``mplplot.png``, ``pb_bem.png`` (with the BEM markers of ``--vr RUNS``),
                    ``b1.png``, ``theory.json`` (beta, m, q1, q2, m2 per n)
``report``          ``REPORT.md`` from every fit.json/JSON and results file under ``--results``
=================  =========================================================================

Every number written comes from a results file of ``sweep run`` or from :mod:`sweep.theory`;
the paper's values (``tests/data/paper_values.yaml``) enter the report's comparison column only.
Bad input: one line ``error: ...`` and exit 2.
"""
from __future__ import annotations

import json
import os
import re
import subprocess
import sys
from pathlib import Path

import click
import numpy as np
import yaml

from ..errors import InputError, writing
from .report import build_report

PAPER_VALUES = Path(__file__).resolve().parents[2] / "tests" / "data" / "paper_values.yaml"


def _load_results(path):
    from ..campaign.store import load_results

    return load_results(path)


def _provenance(path) -> dict:
    """Where a fit came from: the results file and the attributes its writer recorded."""
    from ..campaign.store import read_attrs

    a = read_attrs(path)
    keep = ("config_name", "config_source", "config_hash", "git_commit", "n_scenes", "n_finished", "complete",
            "started_at", "updated_at", "finished_at", "package_version", "numba_version")
    return {"results": str(path), **{k: a.get(k) for k in keep}}


def _engine_check(runs) -> dict:
    """What the campaign's rows were computed with and a sample of them
    (:mod:`sweep.paper.engine_check`), which ``make test`` computes again."""
    from .engine_check import record

    return record(runs)


def _cost(df) -> dict:
    """Scene counts and costs of a runs table (seconds)."""
    ok = df["status"] == "ok"
    return {"scenes": int(len(df)), "ok": int(ok.sum()), "failed": int((~ok).sum()),
            "failures": [{"scene_id": r.scene_id, "reason": r.reason}
                         for r in df[~ok].itertuples()],
            "scene_wall_s_sum": float(df["wall_s"].sum()),
            "scene_cpu_s_sum": (float(df["task_cpu_s"].sum()) if "task_cpu_s" in df
                                else float("nan")),
            "scene_wall_s_max": float(df["wall_s"].max())}


def _links_from(text: str, root: Path, where: Path) -> str:
    """The report's relative links (figures, sub-reports: relative to the results directory
    ``root``) as seen from ``where``, the folder it is written to (written elsewhere with
    --out they had pointed nowhere)."""
    prefix = os.path.relpath(root.resolve(), where.resolve())
    if prefix == ".":
        return text
    return re.sub(r"\]\((?![a-z][a-z0-9+.-]*:|#|/)([^)\s]+)\)",
                  lambda m: f"]({Path(prefix, m.group(1)).as_posix()})", text)


def _outdir(outdir) -> Path:
    """The output directory OUTDIR, created: InputError (one line) where it is a file or
    cannot be created (a FileExistsError traceback had ended the command)."""
    out = Path(outdir)
    if out.exists() and not out.is_dir():
        raise InputError(f"outdir: {outdir} is a file; give a directory")
    with writing("outdir", out, "create"):
        out.mkdir(parents=True, exist_ok=True)
    return out


def _write_json(obj, path: Path) -> Path:
    from ..campaign.store import to_jsonable

    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_suffix(".json.tmp")
    tmp.write_text(json.dumps(to_jsonable(obj), indent=1, allow_nan=False) + "\n")
    tmp.replace(path)
    return path


def _paper() -> dict:
    return yaml.safe_load(PAPER_VALUES.read_text())


def _fit_campaign(runs, outdir, analyze):
    """Load RUNS, fit it with ``analyze(df) -> dict``, add provenance and cost, write
    OUTDIR/fit.json; returns (runs table, fit dict, OUTDIR as a Path)."""
    df = _load_results(runs)
    fit = analyze(df)
    fit.update(provenance=_provenance(runs), cost=_cost(df), engine_check=_engine_check(runs))
    out = _outdir(outdir)
    _write_json(fit, out / "fit.json")
    return df, fit, out


@click.group("reproduce", context_settings={"help_option_names": ["-h", "--help"]})
def cli():
    """Fits, figures and the report of the paper's campaigns (called by the Makefile)."""


@cli.command("threshold")
@click.argument("runs")
@click.argument("outdir")
def threshold_cmd(runs, outdir):
    """fit.json and threshold.png of the threshold-radius sweep RUNS."""
    from ..analysis import fits as analysis
    from .figures import threshold_figure

    p = _paper()["threshold_radius"]["collapse_fit"]
    paper = (float(p["prefactor"]), float(p["exponent"]))
    df, fit, out = _fit_campaign(runs, outdir,
                                 lambda d: analysis.threshold_analysis(d, paper_fit=paper))
    threshold_figure(df, fit, out / "threshold.png", paper=paper)
    pp = fit["paper_protocol"]

    def ci(c):                         # no interval: too few points (fits.MIN_BOOT_POINTS)
        return "[-]" if c is None else f"[{c[0]:.4g}, {c[1]:.4g}]"

    paper_text = ("paper protocol: fewer than 3 points" if pp is None else
                  f"paper protocol: A = {pp['A']:.4g} {ci(pp['A_ci'])}, B = {pp['B']:.4g} "
                  f"{ci(pp['B_ci'])}, A_no_pi = {pp['A_no_pi']:.4g}, {pp['n_points']} points")
    click.echo(f"{out / 'fit.json'}: A = {fit['prefactor']:.4g} {ci(fit['prefactor_ci'])}, "
               f"B = {fit['exponent']:.4g} {ci(fit['exponent_ci'])}, {fit['n_points']} points; "
               f"{paper_text}")


@cli.command("vr")
@click.argument("runs")
@click.argument("outdir")
def vr_cmd(runs, outdir):
    """fit.json, v_vs_r.png and pb_vs_bem.png of the crack speed sweep RUNS."""
    from ..analysis import fits as analysis
    from .figures import pb_vs_bem_figure, vr_figure

    p = _paper()["pb_theory"]["v_vs_r_fit"]
    paper = (p["prefactor"], p["exponent"])
    df, fit, out = _fit_campaign(runs, outdir,
                                 lambda d: analysis.vr_analysis(d, paper_fit=paper))
    pts = analysis.paper_variables(analysis.finished(df))
    vr_figure(pts, fit, out / "v_vs_r.png", paper=paper)
    # PB against the BEM, the SLS scenes included as in the paper's figure
    cpts = analysis.pb_points(pts[pts["vhat"] > 0], fit["prefactor"], fit["exponent"])
    pb_vs_bem_figure(cpts, fit["pb_vs_bem"], out / "pb_vs_bem.png")
    pr = fit["paper_range"]
    click.echo(f"{out / 'fit.json'}: vhat = {fit['prefactor']:.4g} rhat_PB^{fit['exponent']:.4g}, "
               f"PB within 15 %: {fit['pb_share_within_15pct']:.3f}, "
               f"alpha_best = {fit['alpha_best']:.4g}; paper's rate range "
               f"{pr['rate_range']}: vhat = {pr['prefactor']:.4g} rhat_PB^{pr['exponent']:.4g}")


@cli.command("fig3")
@click.argument("runs")
@click.argument("outdir")
def fig3_cmd(runs, outdir):
    """fig3.png: the P(a) trajectories of the Fig. 3 sweep RUNS."""
    from .figures import fig3_figure, fig3_panels
    from ..campaign.store import load_trajectory

    df = _load_results(runs)
    trajs = {}
    for sid in df.loc[df["status"] == "ok", "scene_id"]:
        try:
            trajs[sid] = load_trajectory(runs, sid)
        except (KeyError, FileNotFoundError):
            continue
    if not trajs:
        n_ok = int((df["status"] == "ok").sum())
        raise InputError(f"results: {runs!r} holds no trajectory of an ok scene ({n_ok} ok of "
                         f"{len(df)}; a sweep keeps them with store: {{trajectories: true}})")
    panels = fig3_panels(df[df["status"] == "ok"])
    if not any(panels):
        raise InputError(f"results: {runs!r} holds none of Fig. 3's scenes (n 0.8 at a0 3.61, "
                         f"a0 3.61 at rate 10^2.5, n 1.6 at rate 10^2.5: configs/fig3.yaml)")
    out = _outdir(outdir)
    fig3_figure(df, trajs, out / "fig3.png")
    ok = df[df["status"] == "ok"]
    _write_json({"provenance": _provenance(runs), "cost": _cost(df),
                 "engine_check": _engine_check(runs),
                 "pull_off": [{"n": r.n, "a0": r.a0, "rate": r.rate, "pull_off": r.pull_off}
                              for r in ok.itertuples()]}, out / "fig3.json")
    click.echo(str(out / "fig3.png"))


@cli.command("aconv")
@click.argument("runs")
@click.argument("outdir")
def aconv_cmd(runs, outdir):
    """aconv.png: pull-off vs rate for several a0 (sweep RUNS)."""
    from .figures import aconv_figure

    df = _load_results(runs)
    out = _outdir(outdir)
    aconv_figure(df, out / "aconv.png")
    ok = df[df["status"] == "ok"].sort_values(["a0", "rate"])
    _write_json({"provenance": _provenance(runs), "cost": _cost(df),
                 "engine_check": _engine_check(runs),
                 "pull_off": [{"a0": r.a0, "rate": r.rate, "pull_off": r.pull_off}
                              for r in ok.itertuples()]}, out / "aconv.json")
    click.echo(str(out / "aconv.png"))


@cli.command("theory")
@click.argument("outdir")
@click.option("--vr", "vr_runs", default=None, help="v_vs_r results file for the BEM markers.")
def theory_cmd(outdir, vr_runs):
    """mplplot.png, pb_bem.png, b1.png and theory.json (Persson-Brener power laws)."""
    from ..analysis import fits as analysis
    from .figures import b1_figure, mplplot_figure, pb_bem_figure
    from ..theory import pb_gamma_eff

    if vr_runs is not None:           # read first: a bad file writes no figure
        pts = analysis.paper_variables(analysis.finished(
            analysis.bem_rows(_load_results(vr_runs), "the BEM markers of pb_bem.png")))
    else:
        import pandas as pd

        pts = pd.DataFrame(columns=["material", "n", "k", "vhat", "gamma_eff"])
    out = _outdir(outdir)
    mplplot_figure(out / "mplplot.png")
    k = 0.1
    v = np.logspace(-4, 8, 400)
    ns = [0.2, 0.4, 0.6, 0.8, 1.6]
    curves = {n: (v, np.asarray(pb_gamma_eff(n, k, v))) for n in ns}
    curves["sls"] = (v, np.asarray(analysis.pb_gamma_eff_scene("sls", 1.0, k, v)))
    laws = {n: analysis.pb_power_law(n, k) for n in ns}
    pb_bem_figure(curves, laws, pts, out / "pb_bem.png", k=k)
    p = _paper()["pdms_experiment"]
    k_b1 = float(p["k"])
    ns_b1 = [0.2, 0.4, 0.6, 0.8, 1.0, 1.2, 1.6]
    regimes = {n: analysis.pb_regimes(n, k_b1) for n in ns_b1}
    vb = np.logspace(-4, 8, 400)
    b1_figure({n: (vb, np.asarray(pb_gamma_eff(n, k_b1, vb))) for n in ns_b1}, regimes,
              out / "b1.png", k=k_b1)
    slope, icept = np.polyfit(ns_b1, [regimes[n]["q1"] for n in ns_b1], 1)
    _write_json({"pb_power_law": {"k": k, "laws": [{"n": n, **laws[n]} for n in ns]},
                 "b1": {"k": k_b1, "k_source": "the paper's PDMS k (B1 does not state its k)",
                        "regimes": [{"n": n, **regimes[n]} for n in ns_b1],
                        "q1_linear_fit": {"intercept": float(icept), "slope": float(slope)}}},
                out / "theory.json")
    click.echo(f"{out}: mplplot.png pb_bem.png b1.png theory.json")


@cli.command("report")
@click.option("--results", "results_dir", default="results", show_default=True)
@click.option("--out", "out", default=None, help="Default: RESULTS/REPORT.md.")
def report_cmd(results_dir, out):
    """REPORT.md: every fit beside the paper's value, the figures, counts, failures, times."""
    root = Path(results_dir)
    if not root.is_dir():
        raise InputError(f"results: no such directory {results_dir!r}")
    path = Path(out) if out else root / "REPORT.md"
    text = _links_from(build_report(root, _paper(), _git_commit()), root, path.parent)
    with writing("out", path):
        path.write_text(text)
    click.echo(str(path))


def _git_commit() -> str:
    try:
        head = subprocess.run(["git", "rev-parse", "HEAD"], capture_output=True, text=True,
                              timeout=10, cwd=Path(__file__).resolve().parent).stdout.strip()
        dirty = subprocess.run(["git", "status", "--porcelain", "--untracked-files=no"],
                               capture_output=True, text=True, timeout=10,
                               cwd=Path(__file__).resolve().parent).stdout.strip()
    except (OSError, subprocess.SubprocessError):
        return "unknown"
    return (head or "unknown") + ("-dirty" if dirty else "")


if __name__ == "__main__":
    # run as a program (python -m sweep.paper.reproduce ARGS): `sweep reproduce ARGS`, with
    # the CLI's error mapping (exit 2 on bad input, one line)
    from sweep.cli import main

    sys.exit(main(["reproduce", *sys.argv[1:]]))
