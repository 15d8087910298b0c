"""The ``sweep`` command line: a click group with one command per task.

Every command validates its input through :mod:`sweep.errors`; an invalid
value prints one line ``error: <parameter> must be ... (got ...)`` on stderr
and exits with code 2 (runtime failures exit 1). No traceback is shown.
"""
from __future__ import annotations

import json
import sys

import click
import numpy as np

from .errors import InputError


def parse_floats(name: str, text: str) -> list[float]:
    """Parse a comma-separated list of numbers given to option ``name``."""
    from .errors import as_float

    items = [s for s in text.split(",") if s.strip()]
    if not items:
        raise InputError(f"{name} must be a comma-separated list of numbers (got {text!r})")
    return [as_float(name, s.strip()) for s in items]


def to_jsonable(obj):
    """Recursively convert numpy arrays/scalars so ``json.dumps`` accepts them."""
    if isinstance(obj, dict):
        return {str(k): to_jsonable(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [to_jsonable(v) for v in obj]
    if isinstance(obj, np.ndarray):
        return to_jsonable(obj.tolist())
    if isinstance(obj, np.generic):
        return obj.item()
    if isinstance(obj, float) and not np.isfinite(obj):
        return None
    return obj


def echo_json(obj) -> None:
    click.echo(json.dumps(to_jsonable(obj), indent=None))


@click.group(context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(package_name="visco-sweep")
def cli():
    """Viscoelastic adhesive contact of a sphere: BEM scenes, sweeps and theory."""


# ----------------------------------------------------------------------------
# Commands are added below, one section per concept. Edit with str_replace only.
# ----------------------------------------------------------------------------

# == theory & materials commands (pb, material) ==
def _floats_in(name: str, text: str, lo=None, lo_open=False) -> np.ndarray:
    """A comma list given to option ``name``, every value checked >= lo (> lo if lo_open)."""
    from .errors import check_array

    return check_array(name, parse_floats(name, text), lo=lo, lo_open=lo_open)


@cli.command()
@click.option("--n", "n_text", required=True, help="MPL exponent n, in (0, 10].")
@click.option("--k", "k_text", required=True, help="E0/Einf, in (0, 1].")
@click.option(
    "--v", "v_text", required=True, help="Crack speeds vhat = v tau0/l0 (>= 0), comma list."
)
@click.option("--json", "as_json", is_flag=True, help="Print one JSON object instead of a table.")
def pb(n_text, k_text, v_text, as_json):
    """Persson-Brener effective surface energy Gamma_eff(vhat) of the MPL spectrum."""
    from .errors import as_float
    from .theory import pb_gamma_eff

    n, k = as_float("n", n_text), as_float("k", k_text)
    v = _floats_in("v", v_text, lo=0.0)
    g = np.atleast_1d(pb_gamma_eff(n, k, v))
    if as_json:
        echo_json({"n": n, "k": k, "vhat": v, "gamma_eff": g})
        return
    click.echo(f"# Persson-Brener, MPL retardation spectrum: n = {n:g}, k = {k:g}")
    click.echo(f"{'vhat':>14} {'gamma_eff':>20}")
    for vi, gi in zip(v, g):
        click.echo(f"{vi:>14.6g} {gi:>20.12g}")


@cli.command()
@click.option("--n", "n_text", default=None, help="MPL exponent n (model mpl only).")
@click.option("--k", "k_text", required=True, help="E0/Einf, in (0, 1].")
@click.option(
    "--t", "t_text", required=True,
    help="Times t/tau0 (> 0), comma list; [min t, max t] is also the Prony window.",
)
@click.option(
    "--model", "model", default="mpl", show_default=True, help="mpl (retardation spectrum) or sls."
)
@click.option(
    "--rtol", "rtol_text", default="1e-6", show_default=True,
    help="Prony bound on max |series - Chat| / Chat over the window.",
)
@click.option(
    "--json", "as_json", is_flag=True,
    help="Print one JSON object (prony times: null = inf, the lumped glassy constant).",
)
def material(n_text, k_text, t_text, model, rtol_text, as_json):
    """Normalized creep compliance Chat(t) and its Prony series over [min t, max t].

    E0 = 1, Einf = 1/k, tau0 = 1: times in units of tau0, Chat = C/C0 (Chat(inf) = 1).
    Parameter ranges are those of sweep.materials.
    """
    from . import materials
    from .errors import check_choice

    model = check_choice("model", model, ["mpl", "sls"])
    if model == "mpl":
        if n_text is None:
            raise InputError("n must be given for model mpl (--n, a number > 0)")
        mat = materials.MPLRetardation.from_k(n_text, k_text)
    else:
        mat = materials.SLS.from_k(k_text)
    t = _floats_in("t", t_text, lo=0.0, lo_open=True)
    if not t.max() > t.min():
        raise InputError(
            f"t must hold at least two distinct times, the Prony window (got {t_text!r})"
        )
    chat = np.atleast_1d(mat.normalized_creep_compliance(t))
    series = mat.prony(float(t.min()), float(t.max()), rtol_text)
    n = getattr(mat, "n", None)
    if as_json:
        echo_json(
            {
                "model": model, "n": n, "k": mat.k, "t": t, "chat": chat,
                "prony": {
                    "n_terms": series.n_terms, "max_rel_error": series.max_rel_error,
                    "rtol": series.rtol, "converged": series.converged,
                    "weights": series.weights, "times": series.times,
                },
            }
        )
        return
    head = f"n = {n:g}, " if n is not None else ""
    click.echo(f"# {model}: {head}k = {mat.k:g}; times in tau0, Chat = C/C0")
    click.echo(f"{'t':>14} {'chat':>20}")
    for ti, ci in zip(t, chat):
        click.echo(f"{ti:>14.6g} {ci:>20.12g}")
    click.echo(
        f"# Prony series on [{t.min():g}, {t.max():g}]: n_terms = {series.n_terms}, "
        f"max_rel_error = {series.max_rel_error:.3g} (rtol {series.rtol:g}, "
        f"converged {series.converged})"
    )
    click.echo("# Chat ~ 1 - sum weight exp(-t/time); time inf = lumped glassy constant")
    click.echo(f"{'weight':>20} {'time':>14}")
    for wi, ti in zip(series.weights, series.times):
        click.echo(f"{wi:>20.12g} {ti:>14.6g}")


# == single scene command (scene) ==

@cli.command("scene")
@click.option("--n", "n", type=str, default="0.8", show_default=True, help="MPL exponent n.")
@click.option("--k", "k", type=str, default="0.1", show_default=True, help="E0/Einf.")
@click.option("--mu", "mu", type=str, default="3.24", show_default=True, help="Tabor parameter.")
@click.option("--a0", "a0", type=str, default=None, help="Initial contact radius (a_ref units).")
@click.option("--delta0", "delta0", type=str, default=None,
              help="Initial indentation (d_ref units); alternative to --a0.")
@click.option("--rate", "rate", type=str, required=True, help="Unloading rate r-hat = r tau0/h0.")
@click.option("--material", type=click.Choice(["mpl", "sls"]), default="mpl", show_default=True)
@click.option("--stop", type=click.Choice(["pulloff", "separation"]), default="pulloff",
              show_default=True)
@click.option("--preset", type=click.Choice(["fast", "balanced", "accurate"]), default="balanced",
              show_default=True)
@click.option("--nodes", type=str, default=None, help="Override the preset's node count.")
@click.option("--domain", type=str, default=None, help="Mesh radius (a_ref); default automatic.")
@click.option("--step", type=str, default=None, help="Largest indentation step (units of h0).")
@click.option("--exact", is_flag=True, help="Exact hereditary integral instead of Prony (slow).")
@click.option("--json", "as_json", is_flag=True, help="Print one JSON object.")
@click.option("--trajectory", is_flag=True, help="With --json, include the trajectory arrays.")
def scene_command(n, k, mu, a0, delta0, rate, material, stop, preset, nodes, domain, step, exact,
                  as_json, trajectory):
    """Simulate one scene and print pull-off force, contact radius and crack speed."""
    from .errors import as_float
    from .scene import Numerics, Scene
    from .solver import simulate

    sc = Scene(n=as_float("n", n), k=as_float("k", k), mu=as_float("mu", mu),
               a0=None if a0 is None else as_float("a0", a0),
               delta0=None if delta0 is None else as_float("delta0", delta0),
               rate=as_float("rate", rate), material=material, stop=stop)
    overrides = {}
    if nodes is not None:
        try:
            overrides["nodes"] = int(nodes.strip())
        except ValueError:
            raise InputError(f"nodes must be an integer (got {nodes!r})") from None
    if domain is not None:
        overrides["domain"] = as_float("domain", domain)
    if step is not None:
        overrides["step"] = as_float("step", step)
    if exact:
        overrides["exact"] = True
    num = Numerics.preset(preset, **overrides)
    res = simulate(sc, num)
    if as_json:
        echo_json(res.to_dict(trajectory=trajectory))
    else:
        click.echo(f"scene      n={sc.n:g} k={sc.k:g} mu={sc.mu:g} rate={sc.rate:g} "
                   f"{'a0=' + format(sc.a0, 'g') if sc.a0 is not None else 'delta0=' + format(sc.delta0, 'g')}"
                   f" material={sc.material}")
        click.echo(f"numerics   preset={preset} mesh={num.mesh} nodes={res.nodes_used} spacing={res.spacing:.4g} "
                   f"domain={res.domain_used:.4g} prony_terms={res.prony_terms}")
        click.echo(f"status     {res.status}{' (' + res.reason + ')' if res.reason else ''}")
        click.echo(f"initial    a0={res.a0_result:.6g} a0_inner={res.a0_inner:.6g} "
                   f"delta0={res.delta0_result:.6g}")
        if res.ok:
            click.echo(f"pull-off   P={res.pull_off:.6g} (pi dg R)  a={res.a_pulloff:.6g}  "
                       f"a_inner={res.a_inner_pulloff:.6g}  delta={res.delta_pulloff:.6g}")
            click.echo(f"crack      v_a={res.crack_speed:.6g} (a_ref/tau0)  vhat={res.vhat:.6g}  "
                       f"rhat_pb={res.rhat_pb:.6g}")
        click.echo(f"cost       steps={res.steps} newton={res.newton_iterations} "
                   f"factorizations={res.factorizations} wall={res.wall_s:.3f} s")
    if not res.ok:
        raise SystemExit(1)


@cli.command("plot")
@click.argument("results")
@click.option("--out", default=None, help="Output PNG (default: RESULTS with suffix .png).")
def plot_command(results, out):
    """Plot pull-off vs rate (and P(a) trajectories, if stored) of a results file."""
    from pathlib import Path

    from .plots import plot_sweep

    if not Path(results).exists():
        raise InputError(f"results: no such file {results!r}")
    click.echo(str(plot_sweep(results, out)))

# == sweep commands (run, info) ==
@cli.command("run")
@click.argument("config")
@click.option("-j", "--jobs", type=int, default=None,
              help="Worker processes (loky; default: all cores) or tasks in flight (dask).")
@click.option("--backend", type=click.Choice(["loky", "dask"]), default="loky",
              show_default=True, help="joblib backend: local processes or a dask cluster.")
@click.option("--scheduler", default=None, metavar="ADDR",
              help="dask scheduler address, e.g. tcp://head:8786 (with --backend dask; "
                   "without it a local dask cluster is started).")
@click.option("--out", default=None, metavar="PATH",
              help="Results file (overrides the config's output).")
@click.option("--resume/--fresh", default=True, show_default=True,
              help="Resume: skip scenes already in the results file. Fresh: move the old "
                   "file aside to <out>.bak and start over.")
@click.option("--progress", type=click.Choice(["auto", "bar", "log", "none"]), default="auto",
              show_default=True, help="Progress display (auto: a bar on a TTY, else one "
                                      "line per scene).")
@click.option("--connect-timeout", type=float, default=10.0, show_default=True,
              help="Seconds to wait for the dask scheduler.")
@click.option("--consolidate-every", type=float, default=5.0, hidden=True,
              help="Seconds between consolidations of the results file (tests).")
def run_cmd(config, jobs, backend, scheduler, out, resume, progress, connect_timeout,
            consolidate_every):
    """Run (or resume) the sweep described by the YAML file CONFIG."""
    from .scheduler import SweepRuntimeError, run_sweep

    try:
        report = run_sweep(config, jobs=jobs, backend=backend, scheduler=scheduler, out=out,
                           resume=resume, progress=progress, connect_timeout=connect_timeout,
                           consolidate_every=consolidate_every)
    except SweepRuntimeError as exc:
        raise click.ClickException(" ".join(str(exc).split())) from None
    click.echo(report.line())


@cli.command("info")
@click.argument("results")
@click.option("--slowest", type=int, default=5, show_default=True,
              help="How many of the slowest scenes to list.")
def info_cmd(results, slowest):
    """Summarize a results file: counts by status, parameter ranges, slowest scenes."""
    from .store import summary

    try:
        text = summary(results, slowest=slowest)
    except FileNotFoundError:
        raise InputError(f"no results at {results}") from None
    click.echo(text)



def main(argv=None) -> int:
    """Entry point: run the click group, mapping errors to one line + exit code."""
    try:
        cli.main(args=argv, standalone_mode=False)
    except InputError as exc:
        click.echo(f"error: {exc}", err=True)
        return 2
    except click.exceptions.Abort:
        click.echo("error: aborted", err=True)
        return 130
    except click.ClickException as exc:
        msg = exc.format_message().replace("\n", " ")
        click.echo(f"error: {msg}", err=True)
        return exc.exit_code if exc.exit_code else 2
    except SystemExit as exc:  # --help / --version
        return exc.code if isinstance(exc.code, int) else 0
    return 0


def entry() -> None:
    sys.exit(main())


if __name__ == "__main__":  # pragma: no cover
    entry()
