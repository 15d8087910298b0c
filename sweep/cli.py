"""The ``sweep`` command line: a click group with one command per task.

Every command validates its input through :mod:`sweep.errors`; an invalid
value prints one line ``error: <parameter> must be ... (got ...)`` on stderr
and exits with code 2 (runtime failures exit 1). No traceback is shown. ``sweep run`` exits
with code 3 after a sweep in which scenes hit an internal error (status "error", a bug: their
tracebacks are in ``<out>.errors.log``).

Start-up: this module imports click and the vocabulary only (errors, scene: numpy); each
command imports its machinery (numba, scipy, h5py, pandas ...) in its body, when it runs, and
the ``reproduce`` group (:mod:`sweep.paper.reproduce`) is imported when it is invoked, so that
``sweep --help`` and ``sweep CMD --help`` start at once (tests/test_layout.py).
"""
from __future__ import annotations

import inspect
import json
import math
import shlex
import signal
import sys
import threading
from importlib import import_module
from pathlib import Path

import click
import numpy as np  # loaded anyway by sweep.scene
from click.core import ParameterSource

from .errors import (InputError, as_float, check_array, check_choice, check_int, check_output,
                     check_positive, check_range, writing)
from ._version import __version__
from .scene import (AXES, PRESETS, REFINEMENTS_ON_REQUEST, Numerics, Scene,
                    preset_for_tolerance)

#: exit code of ``sweep run`` when scenes hit an internal error (the sweep itself finished)
EXIT_INTERNAL_ERROR = 3


def parse_floats(name: str, text: str) -> list[float]:
    """Parse a comma-separated list of numbers given to option ``name``."""
    items = [s for s in text.split(",") if s.strip()]
    if not items:
        raise InputError(f"{name} must be a comma-separated list of numbers (got {text!r})")
    return [as_float(name, s.strip()) for s in items]


def echo_json(obj) -> None:
    from .campaign.store import to_jsonable  # h5py: only commands that print JSON pay it

    click.echo(json.dumps(to_jsonable(obj), indent=None))


class LazyGroup(click.Group):
    """A click group some of whose subcommands live in other modules, imported when invoked.

    ``lazy``: {name: ("module:attribute", help)}; ``help`` is the first paragraph of the
    command's own help, what ``--help`` lists without importing the module
    (tests/test_layout.py checks that the two agree).
    """

    def __init__(self, *args, lazy: dict | None = None, **kwargs):
        super().__init__(*args, **kwargs)
        self.lazy = dict(lazy or {})
        self._listing = False

    def list_commands(self, ctx):
        return sorted({*super().list_commands(ctx), *self.lazy})

    def get_command(self, ctx, name):
        if name in self.lazy and name not in self.commands:
            target, help_ = self.lazy[name]
            if self._listing:               # --help of the group: no import
                return click.Command(name, help=help_)
            module, attr = target.split(":")
            self.add_command(getattr(import_module(module), attr), name)
        return super().get_command(ctx, name)

    def format_commands(self, ctx, formatter):
        self._listing = True
        try:
            super().format_commands(ctx, formatter)
        finally:
            self._listing = False


@click.group(cls=LazyGroup, context_settings={"help_option_names": ["-h", "--help"]},
             lazy={"reproduce": ("sweep.paper.reproduce:cli",
                                 "Fits, figures and the report of the paper's campaigns (called "
                                 "by the Makefile).")})
# the source's version, not the installed metadata (which an editable install keeps at the
# version it was installed with)
@click.version_option(__version__, prog_name="sweep")
def cli():
    """Viscoelastic adhesive contact of a sphere: BEM scenes, sweeps and theory."""


# ----------------------------------------------------------------------------
# Commands, one section per concept. A new command is a new section; shared option
# parsing lives in the helpers above.
# ----------------------------------------------------------------------------

# == theory & materials commands (pb, material) ==
def _floats_in(name: str, text: str, lo=None, lo_open=False) -> np.ndarray:
    """A comma list given to option ``name``, every value checked >= lo (> lo if lo_open)."""
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
    from .theory import pb_gamma_eff

    from .theory import VHAT_MAX

    n, k = as_float("n", n_text), as_float("k", k_text)
    v = _floats_in("v", v_text, lo=0.0)
    if v.max() > VHAT_MAX:       # named by its option (theory names its argument, vhat)
        raise InputError(f"v must be <= {VHAT_MAX:g} (got {v.max():g})")
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

    model = check_choice("model", model, ["mpl", "sls"])
    if model == "mpl":
        if n_text is None:
            raise InputError("n must be given for model mpl (--n, a number > 0)")
        mat = materials.MPLRetardation.from_k(n_text, k_text)
    else:
        if n_text is not None:
            raise InputError("n: the SLS has no exponent (model mpl only); leave --n out")
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

#: The help of a Scene option where the command line takes less than the field: a Prony
#: table is a config's material (or the API's), not a value of ``--material``.
CLI_ONLY_HELP = {
    "material": "creep compliance: MPL retardation spectrum or SLS; mpl, sls (a Prony table "
                "is the material of a config, {prony: file} or inline: docs/configs.md)",
}


def scene_options(func):
    """One option per Scene field, from its metadata (sweep.scene.AXES): name, default,
    allowed values and help are declared once, in sweep/scene.py (:data:`CLI_ONLY_HELP`
    where the option takes less than the field)."""
    for a in reversed(list(AXES.values())):
        # --pz_law and --pz-law alike
        names = dict.fromkeys((f"--{a.name}", f"--{a.name.replace('_', '-')}"))
        if a.numeric:
            default = a.cli_default if a.required else a.default
            option = click.option(
                *names, a.name, type=str,
                default=None if default is None else format(default, "g"),
                show_default=default is not None,
                help=a.describe() + ".")
        else:
            option = click.option(*names, a.name, type=click.Choice(list(a.choices)),
                                  default=a.default, show_default=True,
                                  help=CLI_ONLY_HELP.get(a.name, a.describe()) + ".")
        func = option(func)
    return func


def scene_from_options(values: dict):
    """A Scene from the option strings of :func:`scene_options` (numbers parsed, named)."""
    return Scene(**{name: as_float(name, v) if AXES[name].numeric and v is not None else v
                    for name, v in values.items()})


_SI_OPTIONS = ("R", "E0", "Einf", "nu", "tau0", "dg", "h0", "a0_si", "indentation", "speed",
               "approach_speed")


@cli.command("scene")
@scene_options
@click.option("--si", "si", is_flag=True,
              help="Give the scene in SI units: --n --R --E0 --Einf --nu --tau0 --dg --h0, one "
                   "of --preload/--a0-si/--indentation, and --speed (instead of --k --mu --a0 "
                   "--delta0 --rate); a process zone's --pz-v0 is then in m/s, "
                   "--machine-stiffness in N/m.")
@click.option("--R", "R", type=str, default=None, help="[--si] sphere radius [m].")
@click.option("--E0", "E0", type=str, default=None, help="[--si] relaxed Young's modulus [Pa].")
@click.option("--Einf", "Einf", type=str, default=None, help="[--si] glassy Young's modulus [Pa].")
@click.option("--nu", "nu", type=str, default=None, help="[--si] Poisson's ratio.")
@click.option("--tau0", "tau0", type=str, default=None, help="[--si] MPL time tau0 [s].")
@click.option("--dg", "dg", type=str, default=None, help="[--si] work of adhesion [J/m^2].")
@click.option("--h0", "h0", type=str, default=None, help="[--si] LJ equilibrium distance [m].")
@click.option("--a0-si", "a0_si", type=str, default=None, help="[--si] initial contact radius [m].")
@click.option("--indentation", "indentation", type=str, default=None,
              help="[--si] initial indentation [m].")
@click.option("--speed", "speed", type=str, default=None, help="[--si] unloading speed [m/s].")
@click.option("--approach-speed", "approach_speed", type=str, default=None,
              help="[--si] test protocol: approach speed [m/s] (with --preload [N] and --dwell "
                   "[s]).")
@click.option("--preset", type=click.Choice(list(PRESETS)), default="balanced",
              show_default=True)
@click.option("--pull-off-rtol", "pull_off_rtol", type=str, default=None,
              help="Ask for this relative pull-off accuracy: the cheapest preset that meets it "
                   "(or --preset's), refined where a scene's error estimate says no.")
@click.option("--nodes", type=str, default=None, help="Override the preset's node count.")
@click.option("--domain", type=str, default=None, help="Mesh radius (a_ref); default automatic.")
@click.option("--step", type=str, default=None, help="Largest indentation step (units of h0).")
@click.option("--band-resolution", "band_resolution", type=str, default=None,
              help="Override the preset's fine spacing: tip zone / band_resolution.")
@click.option("--max-nodes", "max_nodes", type=str, default=None,
              help="Override the preset's largest mesh (nodes).")
@click.option("--max-steps", "max_steps", type=str, default=None,
              help="Override the preset's largest number of steps.")
@click.option("--time-budget", "time_budget_s", type=str, default=None,
              help="The scene's time budget [s] (0: none).")
@click.option("--exact", is_flag=True,
              help="Exact hereditary integral instead of Prony (slow), at fixed steps of "
                   "--step h0 without the Prony run's da_max control (docs/scenes.md).")
@click.option("--json", "as_json", is_flag=True, help="Print one JSON object.")
@click.option("--trajectory", is_flag=True, help="With --json, include the trajectory arrays.")
@click.option("--shares", is_flag=True,
              help="With a process zone: also the bulk's and the process zone's shares of the "
                   "pull-off amplification (two more rows: without the zone, relaxed).")
def scene_command(preset, pull_off_rtol, nodes, domain, step, band_resolution, max_nodes,
                  max_steps, time_budget_s, exact, as_json, trajectory, shares, si, **values):
    """Simulate one scene and print pull-off force, contact radius and crack speed."""
    from .engine.models import simulate

    si_values = {name: values.pop(name) for name in _SI_OPTIONS}
    axes = values
    overrides = {}
    if nodes is not None:               # its range: Numerics's
        overrides["nodes"] = check_int("nodes", nodes)
    if domain is not None:
        overrides["domain"] = as_float("domain", domain)
    if step is not None:
        overrides["step"] = as_float("step", step)
    # the knobs a failure's advice names (raise band_resolution, max_nodes, max_steps or
    # time_budget_s); their ranges: Numerics's
    for name, value, read in (("band_resolution", band_resolution, as_float),
                              ("max_nodes", max_nodes, check_int),
                              ("max_steps", max_steps, check_int),
                              ("time_budget_s", time_budget_s, as_float)):
        if value is not None:
            overrides[name] = read(name, value)
    if exact:
        overrides["exact"] = True
    meshless = [f"--{name.replace('_', '-')}" for name in MESH_OPTIONS if name in overrides]
    if axes["model"] in ("crack", "pb") and meshless:      # accepted and ignored, before
        raise InputError(f"{', '.join(meshless)}: model {axes['model']} has no mesh and no "
                         f"time steps (the BEM's and the elastic branch's options)")
    num = _scene_numerics(preset, pull_off_rtol, overrides)
    if (pull_off_rtol is not None and click.get_current_context().get_parameter_source(
            "preset") is not ParameterSource.COMMANDLINE):
        # the accuracy asked for chose the preset it starts from (Numerics.for_tolerance)
        preset = f"{preset_for_tolerance(num.pull_off_rtol)} (from --pull-off-rtol)"
    if shares and (si or axes["pz_law"] in (None, "none")):
        raise InputError("--shares: a dimensionless scene with a process zone (--pz-law "
                         "gent-schultz, --pz-v0, --pz-xi)" + (", not --si" if si else ""))
    if si:
        _scene_si(axes, as_json, si_values, num)
        return
    given = [f"--{name.replace('_', '-')}" for name, v in si_values.items() if v is not None]
    if given:
        raise InputError(f"{', '.join(given)}: SI options need --si")
    missing = [f"--{a.name}" for a in AXES.values()
               if a.required and a.cli_default is None and axes[a.name] is None]
    if missing:
        raise InputError(f"{', '.join(missing)} must be given (or use --si)")
    sc = scene_from_options(axes)
    res = simulate(sc, num)
    split = None
    if shares:
        from .analysis.shares import process_zone_shares

        split = process_zone_shares(sc, num, both=res)
    if as_json:
        echo_json({**res.to_dict(trajectory=trajectory),
                   **({"shares": {k: v for k, v in split.items() if k != "both"}}
                      if split else {})})
    else:
        if sc.protocol() is not None:
            start = (f"approach_rate={sc.approach_rate:g} preload={sc.preload:g} "
                     f"dwell={sc.dwell:g} ({sc.dwell_hold})")
        else:
            start = f"a0={sc.a0:g}" if sc.a0 is not None else f"delta0={sc.delta0:g}"
        machine = ("" if sc.machine_stiffness is None
                   else f" machine_stiffness={sc.machine_stiffness:g}")
        click.echo(f"scene      n={sc.n:g} k={sc.k:g} mu={sc.mu:g} rate={sc.rate:g} {start}"
                   f" material={sc.material} model={sc.model}{machine}")
        for line in scene_text(res, preset):
            click.echo(line)
        if split:
            click.echo(shares_text(split))
    if not res.ok:
        raise SystemExit(1)


def shares_text(split: dict) -> str:
    """``sweep scene --shares``'s line (:func:`sweep.analysis.shares.process_zone_shares`)."""
    rows = ", ".join(f"{name} P={split[name]['pull_off']:.6g} ({split[name]['model']}, "
                     f"{split[name]['status']})" for name in ("bulk", "relaxed")
                     if name in split)
    if not math.isfinite(split["bulk_share"]):
        return f"shares     none: {split['note']}" + (f" [{rows}]" if rows else "")
    head = (f"shares     bulk {split['bulk_share']:.4g}, process zone "
            f"{split['process_zone_share']:.4g} of ln(P/P_relaxed), amplification "
            f"{split['amplification']:.6g}, share error {split['share_error']:.2g}")
    return head + (f"; {split['note']}" if split["note"] else "") + f" [{rows}]"


#: `sweep scene`'s numerics options that only a model with a mesh reads (bem, elastic)
MESH_OPTIONS = ("nodes", "domain", "step", "band_resolution", "max_nodes", "max_steps", "exact")


def _scene_numerics(preset: str, pull_off_rtol: str | None, overrides: dict) -> Numerics:
    """The numerics of ``sweep scene``: the preset, or with ``--pull-off-rtol`` an accuracy
    asked for (:meth:`Numerics.for_tolerance`; with ``--preset`` given, that preset at the
    tolerance, with the same refinements)."""
    if pull_off_rtol is None:
        return Numerics.preset(preset, **overrides)
    rtol = check_range("pull_off_rtol", pull_off_rtol, 0.0, 1.0, lo_open=True)
    source = click.get_current_context().get_parameter_source("preset")
    if source is ParameterSource.COMMANDLINE:
        return Numerics.preset(preset, pull_off_rtol=rtol, refinements=REFINEMENTS_ON_REQUEST,
                               **overrides)
    return Numerics.for_tolerance(rtol, **overrides)


def _finite(**values) -> str:
    """``name=value`` (6 significant digits) for each finite value, space separated: the
    fields a model does not compute (NaN) are left out."""
    return "  ".join(f"{name}={v:.6g}" for name, v in values.items() if math.isfinite(v))


def scene_numerics(res, preset: str) -> tuple[str, str]:
    """The numerics and the cost of ``res`` in the terms of the model that ran it.

    bem: the mesh (graded, uniform or tip-following), its nodes, fine spacing and radius,
    the Prony terms; elastic: the quasi-static branch's mesh; crack: the Radau integration
    of the crack front with the Persson-Brener Gamma(v) of the scene's spectrum (or the
    nearly elastic closed form); pb: the paper's closed-form estimate, which has none.
    """
    from .engine import crack_front
    from .engine.models import pb_estimate, wants_tip_following

    sc, num = res.scene, res.numerics
    model = res.model_used or sc.model
    wall = f"wall={res.wall_s:.3f} s"
    if model == "pb":
        fit = inspect.signature(pb_estimate).parameters
        return (f"PB estimate, closed form: vhat = {fit['prefactor'].default:g} "
                f"rhat_PB^{fit['exponent'].default:g} (the paper's fit), P = 1.5 "
                f"Gamma_PB(vhat) of the {sc.material} spectrum; no mesh, no time steps",
                wall)
    if model == "crack":
        cost = (f"steps={res.steps} rhs_evaluations={res.newton_iterations} "
                f"lu={res.factorizations} {wall}")
        nearly_elastic = 1.0 / sc.k - 1.0 <= crack_front.NEARLY_ELASTIC * (1.0 + 1e-12)
        if nearly_elastic and sc.pz_law == "none":
            return (f"crack-front model, nearly elastic (1/k - 1 = {1.0 / sc.k - 1.0:.3g} <= "
                    f"{crack_front.NEARLY_ELASTIC:g}): JKR at constant Gamma = "
                    f"{1.0 / math.sqrt(sc.k):.6g} dg, closed form", wall)
        budget = f" time_budget={num.time_budget_s:g} s" if num.time_budget_s > 0 else ""
        bulk = (f"the constant bulk factor {1.0 / math.sqrt(sc.k):.6g} (nearly elastic)"
                if nearly_elastic else f"Persson-Brener Gamma(v) of the {sc.material} spectrum")
        if sc.pz_law != "none":
            bulk = (f"process zone ({sc.pz_law}, pz_v0={sc.pz_v0:g}, pz_xi={sc.pz_xi:g}) "
                    + ("alone (k = 1)" if sc.k == 1.0 else f"times {bulk}"))
        return (f"crack-front model: Radau integration rtol="
                f"{crack_front.unload.__kwdefaults__['rtol']:g}, {bulk} (no mesh){budget}",
                cost)
    nodes = f"nodes={res.nodes_used} spacing={res.spacing:.4g} domain={res.domain_used:.4g}"
    if model == "elastic":
        return (f"elastic branch, quasi-static (k = 1, no hereditary integral): "
                f"preset={preset} {nodes}",
                f"solves={res.steps} newton={res.newton_iterations} {wall}")
    mesh = "tip-following" if wants_tip_following(sc, num) else num.mesh
    return (f"BEM: preset={preset} mesh={mesh} {nodes} prony_terms={res.prony_terms}",
            f"steps={res.steps} newton={res.newton_iterations} "
            f"factorizations={res.factorizations} {wall}")


def scene_text(res, preset: str) -> list[str]:
    """The lines of ``sweep scene``'s text output after the scene line: the model's own
    numerics, the status, the model, the initial state, pull-off and crack speed (the fields
    the model computes), a test protocol's hysteresis energy and its error, and the cost."""
    numerics, cost = scene_numerics(res, preset)
    why = f"  ({res.model_reason})" if res.model_used != res.scene.model else ""  # auto
    lines = [f"numerics   {numerics}",
             f"status     {res.status}{' (' + res.reason + ')' if res.reason else ''}",
             f"model      {res.model_used}{why}"]
    initial = _finite(a0=res.a0_result, a0_inner=res.a0_inner, delta0=res.delta0_result)
    if initial:
        lines.append(f"initial    {initial}")
    from .engine.resolution import unresolved   # (the engine is loaded: res was run)

    if unresolved(res) and math.isfinite(res.pull_off):   # the finest value, marked
        lines.append(f"pull-off   P={res.pull_off:.6g} (pi dg R), unresolved: "
                     f"error_estimate={res.error_estimate:.3g} > pull_off_rtol")
    if res.ok:
        lines.append(f"pull-off   P={res.pull_off:.6g} (pi dg R)  " + _finite(
            a=res.a_pulloff, a_inner=res.a_inner_pulloff, delta=res.delta_pulloff,
            error_estimate=res.error_estimate))
        lines.append(f"crack      v_a={res.crack_speed:.6g} (a_ref/tau0)  "
                     + _finite(vhat=res.vhat, rhat_pb=res.rhat_pb))
        if math.isfinite(res.hysteresis_energy):      # a test protocol's cycle
            lines.append(f"cycle      hysteresis_energy={res.hysteresis_energy:.6g} (pi dg R "
                         f"d_ref)  " + _finite(hysteresis_error=res.hysteresis_error))
    lines.append(f"cost       {cost}")
    return lines


def _scene_si(axes, as_json, values, numerics):
    """``sweep scene --si``: build an SIScene, run it at ``numerics``, print both unit
    systems."""
    from .campaign.si import run_si, si_point

    ctx = click.get_current_context()
    clash = [f"--{name}" for name in ("k", "mu", "a0", "delta0", "rate", "approach_rate")
             if ctx.get_parameter_source(name) == ParameterSource.COMMANDLINE]
    if clash:
        raise InputError(f"{', '.join(clash)}: dimensionless options cannot be combined with "
                         f"--si (give --Einf, --h0, --preload/--a0-si/--indentation, --speed)")
    n, material, model = axes["n"], axes["material"], axes["model"]
    required = ("R", "E0", "Einf", "nu", "tau0", "dg", "h0", "speed")
    missing = [f"--{name}" for name in required if values[name] is None]
    if n is None:
        missing.insert(0, "--n")
    if missing:
        raise InputError(f"{', '.join(missing)} must be given with --si")
    kw = {name: as_float(name, v) for name, v in values.items() if v is not None}
    if axes["preload"] is not None:         # the one --preload: newtons with --si
        kw["preload"] = as_float("preload", axes["preload"])
    if axes["dwell"] is not None:           # and the one --dwell: seconds
        kw["dwell"] = as_float("dwell", axes["dwell"])
    kw["dwell_hold"] = axes["dwell_hold"]    # SIScene refuses "depth" without a protocol
    if axes["machine_stiffness"] is not None:     # and --machine-stiffness: N/m
        kw["machine_stiffness"] = as_float("machine_stiffness", axes["machine_stiffness"])
    if "a0_si" in kw:
        kw["a0"] = kw.pop("a0_si")
    pz = {"pz_law": axes["pz_law"], **{name: as_float(name, axes[name])
                                       for name in ("pz_v0", "pz_xi") if axes[name] is not None}}
    # the checks of a `units: si` config's point: the derived scene within the Scene's ranges
    si, _ = si_point({"n": as_float("n", n), "material": material, "model": model,
                      "stop": axes["stop"], **pz, **kw}, "--si")
    out = run_si(si, model, numerics)
    if as_json:
        echo_json(out)
    else:
        click.echo(f"scene      SI -> n={out['scene']['n']:g} k={out['k']:.4g} mu={out['mu']:.4g} "
                   f"rate={out['rate']:.4g} l0={out['l0_m']:.4g} m a_ref={out['a_ref_m']:.4g} m")
        click.echo(f"model      {out['model']}  status {out['status']}"
                   f"{' (' + out['reason'] + ')' if out['reason'] else ''}")
        if out["status"] == "ok" or (str(out["reason"]).startswith("unresolved")
                                     and out.get("pull_off_N") is not None):
            mark = "" if out["status"] == "ok" else ", unresolved"
            click.echo(f"pull-off   {out['pull_off_N']:.6g} N = {out['pull_off']:.6g} pi dg R "
                       f"(relaxed JKR {out['jkr_pull_off_N']:.6g} N){mark}")
            if out["crack_speed_m_s"] is not None:
                click.echo(f"crack      v={out['crack_speed_m_s']:.6g} m/s  vhat={out['vhat']:.6g}")
    if out["status"] != "ok":
        raise SystemExit(1)


@cli.command("plot")
@click.argument("results")
@click.option("--out", default=None,
              help="Output figure, its format the suffix (.png, .svg, .pdf, ...; .png added "
                   "when there is none); default: RESULTS with suffix .png. Prints the path "
                   "written.")
def plot_command(results, out):
    """Plot pull-off vs rate (and P(a) trajectories, if stored) of a results file."""
    from .analysis.plots import plot_sweep

    if not Path(results).exists():
        raise InputError(f"results: no such file {results!r}")
    click.echo(str(plot_sweep(results, out)))

# == sweep commands (run, info) ==
@cli.command("run")
@click.argument("config")
@click.option("-j", "--jobs", type=int, default=None,
              help="Worker processes (default: all cores) or tasks in flight (dask).")
@click.option("--backend", type=click.Choice(["local", "loky", "dask"]), default="local",
              show_default=True,
              help="local: processes on this machine, forked from this one on Linux (else "
                   "loky's); loky: always loky's new interpreters; dask: a dask cluster.")
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
    from .campaign.scheduler import SweepInterrupted, SweepRuntimeError, run_sweep

    # SIGTERM (what `timeout`, a batch system's time limit or `kill` send) ends the sweep as
    # Ctrl-C does: the finished scenes stored, one line saying how to resume
    terminated = []

    def on_sigterm(signum, frame):
        terminated.append(signum)
        raise KeyboardInterrupt

    main_thread = threading.current_thread() is threading.main_thread()
    previous = signal.signal(signal.SIGTERM, on_sigterm) if main_thread else None
    try:
        report = run_sweep(config, jobs=jobs, backend=backend, scheduler=scheduler, out=out,
                           resume=resume, progress=progress, connect_timeout=connect_timeout,
                           consolidate_every=consolidate_every)
    except SweepRuntimeError as exc:
        raise click.ClickException(" ".join(str(exc).split())) from None
    except SweepInterrupted as exc:
        again = ["sweep", "run", config]
        if out is not None:
            again += ["--out", out]
        if backend != "local":
            again += ["--backend", backend] + (["--scheduler", scheduler] if scheduler else [])
        click.echo(f"\n{'terminated' if terminated else 'interrupted'}: {exc.kept} of "
                   f"{exc.total} scenes are kept in {exc.output}; to resume, run: "
                   f"{shlex.join(again)}", err=True)
        raise SystemExit(128 + signal.SIGTERM if terminated else 130) from None
    finally:
        if main_thread:
            signal.signal(signal.SIGTERM, previous)
    click.echo(report.line())
    if report.errors:   # a bug is not a result: the sweep finished, but says so and fails
        click.echo(f"error: {report.error_line()}", err=True)
        raise SystemExit(EXIT_INTERNAL_ERROR)


@cli.command("info")
@click.argument("results")
@click.option("--slowest", type=click.IntRange(min=0), default=5, show_default=True,
              help="How many of the slowest scenes to list.")
@click.option("--si", "as_si", is_flag=True,
              help="A file of a `units: si` config: one line per scene in SI units (speed, "
                   "mu, l0, pull-off and the relaxed JKR pull-off 1.5 pi dg R).")
@click.option("--csv", "csv_out", default=None, metavar="PATH",
              help="With --si (refused without it): also write every SI and dimensionless "
                   "column as CSV.")
def info_cmd(results, slowest, as_si, csv_out):
    """Summarize a results file: counts by status, parameter ranges, slowest scenes."""
    from .campaign.store import si_table, summary

    if not Path(results).exists():
        raise InputError(f"no results at {results}")
    if csv_out and not as_si:
        raise InputError("csv: needs --si (the SI table of a `units: si` results file); the "
                         "dimensionless rows of any file: sweep.load(RESULTS).to_csv(FILE)")
    if as_si:
        df = si_table(results)
        if csv_out:
            check_output("csv", csv_out, [results])
            # opened here, not by pandas: the operating system's reason in the error
            with writing("csv", csv_out), open(csv_out, "w", newline="") as fh:
                df.to_csv(fh, index=False)
        # the SI inputs that vary over the file (besides the speed) get a column each
        varied = [c for c in df.columns if c.startswith("si_") and c != "si_speed"
                  and df[c].nunique(dropna=True) > 1]
        if "si_pz_law" in df and (df["si_pz_law"] != "none").any():   # a process zone's
            varied += [c for c in ("si_pz_law", "si_pz_v0", "si_pz_xi")  # law and parameters
                       if c in df and c not in varied]
        if "si_material" in df and df["si_material"].str.startswith("prony:").any() \
                and "si_material" not in varied:      # a Prony table: its name and hash
            varied.insert(0, "si_material")
        heads = [f"{c[3:]}[{_si_unit(c[3:])}]" if _si_unit(c[3:]) else c[3:] for c in varied]
        width = {c: max([11, *(len(v) for v in df[c] if isinstance(v, str))]) for c in varied}
        click.echo("scene_id          requested  used   status  "
                   + "".join(f"{h:<{width[c]}} " for h, c in zip(heads, varied))
                   + "speed[um/s]  mu       l0[nm]  pull_off[mN]  jkr_pull_off[mN]  "
                     "crack_speed[um/s]")
        for r in df.sort_values(["model_used", *varied, "si_speed"]).to_dict("records"):
            cs = r["crack_speed_m_s"]
            click.echo(f"{r['scene_id']}  {r['model'] or '?':<9}  {r['model_used'] or '-':<5}  "
                       f"{r['status']:<6}  "
                       + "".join(f"{r[c]:<{width[c]}} " if isinstance(r[c], str) else
                                 f"{r[c]:<{width[c]}.4g} " for c in varied)
                       + f"{r['si_speed'] * 1e6:<11.4g}  {r['mu']:<7.4g}  "
                       f"{r['l0_m'] * 1e9:<6.4g}  "
                       f"{(r['pull_off_N'] or math.nan) * 1e3:<12.5g}  "
                       f"{r['jkr_pull_off_N'] * 1e3:<16.5g}  "
                       f"{(cs if cs is not None else math.nan) * 1e6:.4g}")
        return
    try:
        text = summary(results, slowest=slowest)
    except FileNotFoundError:
        raise InputError(f"no results at {results}") from None
    click.echo(text)


def _si_unit(name: str) -> str:
    from .campaign.si import SI_AXES

    info = SI_AXES.get(name)
    return info.unit if info is not None else ""


# == DMA fitting (fit-dma) ==
@cli.command("fit-dma")
@click.argument("csv_file", metavar="FILE.csv")
@click.option("--tref", "tref", type=str, default="20", show_default=True,
              help="Reference temperature [C] of a temperature sweep.")
@click.option("--wlf", "wlf", type=str, default="17.44,51.6,-115", show_default=True,
              help="WLF constants C1,C2[K],Tg[C] (the paper's eq. aT).")
@click.option("--maxwell", "arms", type=str, default="18", show_default=True,
              help="Arms of the generalized Maxwell comparison fit (0: none).")
@click.option("--plot", "plot_out", default=None, metavar="OUT.png",
              help="Plot data and both fits (the paper's Fig. EE; needs matplotlib).")
@click.option("--noise", "noise", type=str, default="0.01", show_default=True,
              help="Relative rms noise of E' and E'' (0.03 = 3 %); the Kramers-Kronig "
                   "tolerance grows with it.")
@click.option("--json", "as_json", is_flag=True, help="Print one JSON object (SI units).")
@click.option("--out", "json_out", default=None, metavar="FIT.json",
              help="Also write that JSON object to FIT.json: a Prony table a scene can read "
                   "(its maxwell arms; sweep.materials.read_prony).")
def fit_dma_command(csv_file, tref, wlf, arms, plot_out, noise, as_json, json_out):
    """Fit the MPL constants (and a generalized Maxwell model) to DMA data.

    FILE.csv holds a master curve (omega_rad_s,E_storage_Pa,E_loss_Pa) or a temperature
    sweep (T_C,f_Hz,E_storage_Pa,E_loss_Pa), shifted to --tref with the WLF equation.
    """
    from .analysis.dma import (KK_FLOOR, KK_NOISE_FACTOR, fit_maxwell, fit_mpl, storage_fall,
                               kramers_kronig_check, plot_dma, read_dma_csv)

    c = parse_floats("wlf", wlf)
    if len(c) != 3:
        raise InputError(f"wlf must be three numbers C1,C2,Tg (got {wlf!r})")
    n_arms = check_int("maxwell", arms, 0, 200)
    if plot_out is not None:                # its format, before the fits
        from .analysis.plots import figure_path

        figure_path("plot", plot_out)
    if json_out is not None:
        check_output("out", json_out, [csv_file])
    data = read_dma_csv(csv_file, T_ref=as_float("tref", tref), wlf=tuple(c))
    ctx = click.get_current_context()
    shifts = [f"--{name}" for name in ("tref", "wlf")
              if ctx.get_parameter_source(name) == ParameterSource.COMMANDLINE]
    if shifts and data.kind == "master":     # given and ignored, silently, before
        raise InputError(f"{', '.join(shifts)}: {csv_file} is a master curve (omega_rad_s, "
                         f"E_storage_Pa, E_loss_Pa); the WLF shift applies to a temperature "
                         f"sweep (T_C, f_Hz, ...)")
    mpl = fit_mpl(data)
    mx = fit_maxwell(data, n_arms) if n_arms > 0 else None
    kk = kramers_kronig_check(data, noise=check_range("noise", as_float("noise", noise),
                                                      0.0, 0.5))
    if plot_out is not None:
        plot_out = str(plot_dma(data, mpl, mx, plot_out, "plot"))    # the path written
    # what a linear viscoelastic solid's data cannot do, and a fit that misses its data (by
    # the Kramers-Kronig check's own tolerance)
    fall = storage_fall(data, kk.noise)
    fit_misses = max(mpl.quality["rms_rel_storage"], mpl.quality["rms_rel_loss"]) > kk.threshold
    out = {"source": csv_file, "kind": data.kind, "points": int(data.omega.size),
           "omega_min_rad_s": float(data.omega.min()),
           "omega_max_rad_s": float(data.omega.max()),
           "T_ref_C": data.T_ref, "wlf": data.wlf,
           "E0": mpl.E0, "Einf": mpl.Einf, "n": mpl.n, "tau0": mpl.tau0, "k": mpl.k,
           "mpl": mpl.to_dict(), "maxwell": None if mx is None else mx.to_dict(),
           "kramers_kronig": kk.to_dict(), "plot": plot_out,
           "storage_falls": fall is not None, "mpl_fit_within_noise": not fit_misses}
    if json_out is not None:
        with writing("out", json_out), open(json_out, "w") as fh:   # numpy scalars as numbers
            fh.write(json.dumps(out, indent=1, default=lambda x: x.item()) + "\n")
    if as_json:
        echo_json(out)
        return
    click.echo(f"# {csv_file}: {data.kind}, {data.omega.size} points, omega "
               f"{data.omega.min():.3g} .. {data.omega.max():.3g} rad/s"
               + (f", shifted to {data.T_ref:g} C (WLF C1={c[0]:g}, C2={c[1]:g}, Tg={c[2]:g})"
                  if data.kind == "temperature" else ""))
    click.echo("MPL retardation fit (value +- one standard error):")
    for name, unit in (("E0", "Pa"), ("Einf", "Pa"), ("n", ""), ("tau0", "s")):
        if name in mpl.at_bound:
            click.echo(f"  {name:<5} = {getattr(mpl, name):.6g} {unit}  at its "
                       f"{mpl.at_bound[name]}: NOT DETERMINED by the data (a bound, not an "
                       f"estimate; no interval)")
        else:
            poor = ("  (poorly determined: one standard error is more than a factor e)"
                    if name != "n" and mpl.rel_stderr[name] > 1.0 else "")
            click.echo(f"  {name:<5} = {getattr(mpl, name):.6g} +- {mpl.stderr[name]:.2g} "
                       f"{unit}{poor}")
    q = mpl.quality
    bound = (f"; {len(mpl.at_bound)} constant(s) at a bound ({', '.join(mpl.at_bound)}): "
             f"widen the frequency range to reach the plateau" if mpl.at_bound else "")
    click.echo(f"  k = E0/Einf = {mpl.k:.4g}; rms relative residual E' {q['rms_rel_storage']:.3g},"
               f" E'' {q['rms_rel_loss']:.3g}; converged {mpl.success}{bound}")
    if fit_misses:
        click.echo(f"  WARNING: the MPL misses these data (rms relative residual above "
                   f"{kk.threshold:.3g} = {KK_FLOOR:g} + {KK_NOISE_FACTOR:g} x the stated noise "
                   f"{kk.noise:g}): its constants describe another material")
    if fall is not None:
        click.echo(f"WARNING: E' falls with frequency, by {fall['fall']:.2g} of it from "
                   f"{fall['omega_from']:.3g} to {fall['omega_to']:.3g} rad/s (more than "
                   f"{fall['limit']:.2g}, what the stated noise {kk.noise:g} explains): a linear "
                   f"viscoelastic solid's storage modulus does not; check the columns and units")
    if mx is not None:
        q = mx.quality
        click.echo(f"Generalized Maxwell, {n_arms} arms ({q['active_arms']} non-zero): "
                   f"E0 = {mx.E0:.6g} Pa, Einf = {mx.Einf:.6g} Pa; rms relative residual "
                   f"E' {q['rms_rel_storage']:.3g}, E'' {q['rms_rel_loss']:.3g}")
    click.echo(f"Kramers-Kronig: E'' implied by E' differs by {kk.rms_modulus:.3g} of |E*| "
               f"rms over {kk.interior_points} interior points ({kk.rms_rel:.3g} rms relative "
               f"to E'', large where the loss tangent is small); tolerance {kk.threshold:.3g} = {KK_FLOOR:g} + {KK_NOISE_FACTOR:g} x "
               f"the stated noise {kk.noise:g} (--noise): "
               f"{'consistent' if kk.consistent else 'NOT consistent'}")
    if plot_out is not None:
        click.echo(f"plot: {plot_out}")
    if json_out is not None:
        click.echo(f"fit: {json_out}")



# == fit commands (fit threshold, fit vr): the paper's fits of a results file ==
def _ci(ci) -> str:
    return "-" if ci is None else f"[{ci[0]:.4g}, {ci[1]:.4g}]"


_fit_options = [
    click.option("--saturation", "saturation", default="0.9", show_default=True,
                 help="Unsaturated: P_po < SATURATION * 1.5/k, in (0, 10]."),
    click.option("--boot", "boot", default="2000", show_default=True,
                 help="Bootstrap resamples for the 95 % intervals (0: none)."),
    click.option("--json", "as_json", is_flag=True, help="Print one JSON object."),
]


def _with_fit_options(fn):
    for opt in reversed(_fit_options):
        fn = opt(fn)
    return fn


def _fit_numbers(saturation: str, boot: str) -> tuple[float, int]:
    return (check_range("saturation", saturation, 0.0, 10.0, lo_open=True),
            check_int("boot", boot, lo=0, hi=1_000_000))


@cli.group("fit")
def fit_group():
    """The paper's fits of a results file (threshold radius collapse, crack speed vs rate)."""


@fit_group.command("threshold")
@click.argument("results")
@click.option("--slope", "slope", default="0.1", show_default=True,
              help="Threshold rule: first a0 where dP_po/da0 < SLOPE (> 0).")
@_with_fit_options
def fit_threshold_cmd(results, slope, saturation, boot, as_json):
    """Threshold radius a0t per (n, rate) and the collapse fit P_po = A a0t^B of an a0 sweep."""
    from .analysis.fits import threshold_analysis
    from .campaign.store import load_results

    slope = check_positive("slope", slope)
    sat, n_boot = _fit_numbers(saturation, boot)
    out = threshold_analysis(load_results(results), slope, sat, n_boot)
    if as_json:
        echo_json(out)
        return
    click.echo(f"# {results}: {out['scenes']} scenes, {out['failed']} failed")
    click.echo(f"# rule: {out['rule']}")
    click.echo(f"P_po = A a0t^B   A = {out['prefactor']:.4g} {_ci(out['prefactor_ci'])}   "
               f"B = {out['exponent']:.4g} {_ci(out['exponent_ci'])}   "
               f"points = {out['n_points']}")
    click.echo(f"a0t as the h = h0 radius: A = {out['prefactor_inner']:.4g} "
               f"{_ci(out['prefactor_inner_ci'])}, B = {out['exponent_inner']:.4g}; "
               f"a0 in (R^2 dg/E0*)^(1/3): A = {out['prefactor_no_pi']:.4g}")
    pp = out["paper_protocol"]
    if pp is None:
        click.echo("paper's protocol: fewer than 3 threshold points with rate >= 10^0.5 below "
                   "0.5 x 1.5/k")
    else:
        click.echo(f"paper's protocol: A = {pp['A']:.4g} {_ci(pp['A_ci'])}   B = "
                   f"{pp['B']:.4g} {_ci(pp['B_ci'])}   points = {pp['n_points']}   A (a0 in "
                   f"(R^2 dg/E0*)^(1/3)) = {pp['A_no_pi']:.4g} {_ci(pp['A_no_pi_ci'])}")
        click.echo(f"# paper's rule: {pp['rule']}")
        for src in pp["sources"]:
            click.echo(f"#   {src['choice']}: {src['paper']}")
        click.echo("B per n (project rule | paper's protocol): " + "; ".join(
            f"n = {a['n']:g}: {a['B']:.3g} ({a['n_points']}) | {b['B']:.3g} ({b['n_points']})"
            for a, b in zip(out["per_n"], pp["per_n"])))
    click.echo(f"{'selection':<42} {'A':>8} {'B':>7} {'B 95 % CI':>18} {'points':>6}")
    for r in out["sensitivity"]:
        click.echo(f"{r['rule']:<42} {r['prefactor']:>8.4g} {r['exponent']:>7.4g} "
                   f"{_ci(r['exponent_ci']):>18} {r['n_points']:>6}")
    click.echo(f"{'n':>5} {'rate':>10} {'a0t':>8} {'P(a0t)':>8} {'P plateau':>9} "
               f"{'status':<14} fit")
    for r in out["table"]:
        click.echo(f"{r['n']:>5g} {r['rate']:>10.4g} {r['a0t']:>8.4g} {r['P_at_a0t']:>8.4g} "
                   f"{r['P_plateau']:>9.4g} {r['status']:<14} {'x' if r['in_fit'] else ''}")


@fit_group.command("vr")
@click.argument("results")
@_with_fit_options
def fit_vr_cmd(results, saturation, boot, as_json):
    """Crack speed at pull-off vs rate, vhat = A rhat_PB^B, and Persson-Brener vs the BEM."""
    from .analysis.fits import vr_analysis
    from .campaign.store import load_results

    sat, n_boot = _fit_numbers(saturation, boot)
    out = vr_analysis(load_results(results), sat, n_boot)
    if as_json:
        echo_json(out)
        return
    u = out["unsaturated"]
    click.echo(f"# {results}: {out['scenes']} scenes, {out['failed']} failed; "
               f"{out['rhat_pb_definition']}")
    click.echo(f"vhat = A rhat_PB^B, all MPL points: A = {out['prefactor']:.4g} "
               f"{_ci(out['prefactor_ci'])}, B = {out['exponent']:.4g} "
               f"{_ci(out['exponent_ci'])}, points = {out['n_points']}")
    click.echo(f"unsaturated (P_po < {sat:g} * 1.5/k): A = {u['prefactor']:.4g} "
               f"{_ci(u['prefactor_ci'])}, B = {u['exponent']:.4g} {_ci(u['exponent_ci'])}, "
               f"points = {u['n_points']}")
    for way, text in (("measured", "Gamma_PB at the measured vhat"),
                      ("predicted", "Gamma_PB at the fitted vhat(rhat_PB)")):
        c = out["pb_vs_bem"][way]
        click.echo(f"{text}: within 15 % {100 * c['share_within_15pct']:.1f} %, median error "
                   f"{100 * c['median_abs_error']:.2f} %, max {100 * c['max_abs_error']:.1f} %")
    a = out["alpha"]
    click.echo(f"alpha_best = {a['alpha_best']:.4g} ({a['alpha_best_over_paper']:.3f} pi/9): "
               f"RMS ln error {a['rms_log_error_best']:.4g} (pi/9: "
               f"{a['rms_log_error_paper_alpha']:.4g})")
    click.echo("alpha_best per k: " + "; ".join(
        f"k = {r['k']:g}: {r['alpha_best']:.4g}" for r in out["alpha_per_k"]))
    pr = out["paper_range"]
    click.echo(f"paper's rate range r-hat in [{pr['rate_range'][0]:g}, {pr['rate_range'][1]:g}]: "
               f"A = {pr['prefactor']:.4g} {_ci(pr['prefactor_ci'])}, B = {pr['exponent']:.4g} "
               f"{_ci(pr['exponent_ci'])}, points = {pr['n_points']}")
    click.echo(f"# paper's rule: {pr['rule']}; {pr['source']}")
    click.echo(f"{'rate':>10} {'rhat_PB':>10} {'vhat/rhat_PB':>13} {'local slope':>12}")
    for r in out["local_slope"]:
        click.echo(f"{r['rate']:>10.4g} {r['rhat_pb']:>10.4g} {r['v_over_r_median']:>13.3g} "
                   f"{r['slope_median']:>12.3g}")


def main(argv=None) -> int:
    """Entry point: run the click group, mapping errors to one line + exit code."""
    try:
        cli.main(args=argv, standalone_mode=False)
    except InputError as exc:
        click.echo("error: " + " ".join(str(exc).split()), err=True)   # always one line
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


# == calibrate (issue 23): the engine inside a fit to measured pull-off against speed ==
@cli.command("calibrate")
@click.argument("config", metavar="FILE.yaml")
@click.option("--json", "as_json", is_flag=True,
              help="Print one JSON object: estimates, intervals, flags, fit, scenes, wall time.")
@click.option("--out", "out_dir", default=None, metavar="DIR",
              help="Write calibration.json, fit.png and profile_<parameter>.png into DIR.")
@click.option("-j", "--jobs", type=int, default=None,
              help="Worker processes for the scenes (default: all cores; 1: this process).")
@click.option("--quiet", is_flag=True, help="No progress lines on stderr.")
def calibrate_cmd(config, as_json, out_dir, jobs, quiet):
    """Fit the free SI parameters of FILE.yaml to measured pull-off force against speed
    (profile-likelihood 95 % intervals; see sweep.analysis.calibrate and the README)."""
    from .analysis.calibrate import (calibrate, load_calibration, summary_lines, to_json,
                                     write_outputs)
    from .errors import check_int

    if jobs is not None:
        check_int("jobs", jobs, 1, 4096)
    cal = load_calibration(config)
    if out_dir is not None:                 # before the fit: a bad DIR fails at once
        with writing("out", out_dir, "create"):
            Path(out_dir).mkdir(parents=True, exist_ok=True)
    progress = None if quiet else (lambda line: click.echo(line, err=True))
    result = calibrate(cal, jobs=jobs, progress=progress)
    paths = write_outputs(result, out_dir) if out_dir is not None else []
    if as_json:
        click.echo(to_json(result, indent=None))
        return
    for line in summary_lines(result):
        click.echo(line)
    for p in paths:
        click.echo(f"wrote {p}")


if __name__ == "__main__":  # pragma: no cover
    entry()
