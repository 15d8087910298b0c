r"""Stability at the extremes of the scene space: every corner of (n, k, rate, a0, mu).

Each scene runs through :func:`sweep.engine.models.simulate` with the model asked for
(``--model``; default "bem" -- the fixed-band or tip-following BEM, the quasi-static branch
for k = 1 -- and "auto", the model chooser) and is judged against physical bounds that do
not come from the BEM:

* lower: the relaxed elastic pull-off from the same a0, on the quasi-static branch
  (:func:`sweep.engine.quasistatic.elastic_pull_off`, mu <= 100; beyond, its mu -> infinity
  limit, JKR under fixed grips from a0); at the slowest rate the pull-off must equal
  it (to ``SLOW_RTOL``): the substrate relaxes faster than it is unloaded;
* upper: 2/k, the pull-off of a crack whose work of adhesion is amplified by the full
  glassy ratio 1/k (JKR 1.5/k, DMT 2/k) -- or, for a large contact unloaded faster than it
  relaxes, the cohesive limit: the relaxed contact is frozen into a flat punch whose
  traction cannot exceed the LJ maximum tension sigma_0 = 16 mu/(9 sqrt(3) pi^(1/3)) over
  the radius a0 plus two tip zones, pi sigma_0 (a0 + 2 l)^2 (units pi dg R); the bound is
  the larger of the two.

Every row is one of :data:`CLASSES`:

* ``ok``: a finite pull-off inside the bounds;
* ``refused``: failed with a physical refusal (:func:`sweep.errors.is_physical_refusal`: the
  scene's physics has no answer, e.g. no stable contact of radius a0);
* ``failed``: failed with any other reason (a resolution, step or time-budget limit);
* ``wrong``: ok with a non-finite pull-off or one outside the bounds, or failed without a
  reason;
* ``error``: an exception escaped ``simulate`` (an internal error when
  :func:`sweep.errors.is_internal_error` calls it a bug); recorded with its traceback.

``python -m sweep.bench.extremes [--quick] [--model bem auto ...]`` (``make extremes
[QUICK=1] [MODEL=...]``) prints the table and a summary model x class, writes
``extremes.json`` (rows and counts per model, date, preset, time budget) and ``summary.md``
to ``--out`` (default ``results/extremes``; ``results/quick/extremes`` with ``--quick``) and
exits 1 if any row is wrong or an error.
"""
from __future__ import annotations

import argparse
import datetime
import itertools
import json
import math
import os
import platform
import re
import subprocess
import sys
import time
import traceback
from functools import lru_cache
from pathlib import Path

import numpy as np

from ..engine.models import simulate
from ..engine.problem import tip_zone
from ..engine.quasistatic import elastic_pull_off
from ..errors import is_internal_error, is_physical_refusal
from ..scene import AXES, MODEL_NAMES, Numerics, Scene
from ..theory import jkr_load, jkr_pull_off_point

N_VALUES = (0.05, 0.2, 2.5)
K_VALUES = (1e-4, 0.5, 0.999)
RATES = (1e-4, 1e9)
#: the smallest a0 Scene accepts, and 15
A0_VALUES = (0.3, 15.0)
MU_VALUES = (0.01, 0.1, 10.0, 100.0)
#: the slowest rate gives the relaxed elastic pull-off to this relative tolerance
SLOW_RTOL = 0.01
#: the bounds hold to this relative tolerance (the BEM's own resolution error)
BOUND_RTOL = 0.01
#: wall-time budget of one scene in the table, s
TIME_BUDGET_S = 60.0
#: numerics preset of the table
PRESET = "balanced"
#: models the table runs by default
DEFAULT_MODELS = ("bem", "auto")
#: the classes of a row, in table order (see the module docstring)
CLASSES = ("ok", "refused", "failed", "wrong", "error")
#: column titles of the classes in the summary
CLASS_TITLES = {"ok": "ok", "refused": "physically refused", "failed": "failed",
                "wrong": "wrong", "error": "internal error"}
#: the largest mu of the quasi-static elastic branch (:func:`elastic_pull_off`); beyond it
#: the lower bound is its mu -> infinity limit, JKR
ELASTIC_MU_MAX = 100.0

#: a covering subset, cheap enough for the quick test suite: every value of every axis
#: at least once, both bounds, both models (fixed band, tip-following), a fast failure
QUICK = (
    dict(n=0.05, k=1e-4, rate=1e9, a0=15.0, mu=0.01),
    dict(n=2.5, k=0.5, rate=1e-4, a0=15.0, mu=0.1),
    dict(n=0.2, k=0.999, rate=1e9, a0=0.3, mu=0.1),
    dict(n=0.2, k=1e-4, rate=1e-4, a0=0.3, mu=10.0),
    dict(n=2.5, k=0.5, rate=1e9, a0=0.3, mu=10.0),
    dict(n=0.05, k=0.999, rate=1e-4, a0=0.3, mu=0.01),
    dict(n=0.2, k=0.5, rate=1e9, a0=15.0, mu=100.0),
)


def all_scenes() -> list[dict]:
    """The full product (144 scenes) as dicts of Scene fields."""
    return [dict(n=n, k=k, rate=rate, a0=a0, mu=mu) for mu, a0, n, k, rate in
            itertools.product(MU_VALUES, A0_VALUES, N_VALUES, K_VALUES, RATES)]


@lru_cache(maxsize=None)
def relaxed_pull_off(mu: float, a0: float) -> float:
    """The relaxed elastic (quasi-static) pull-off from the contact radius a0.

    Up to mu = :data:`ELASTIC_MU_MAX` the quasi-static elastic branch; beyond, its mu ->
    infinity limit, JKR unloaded under fixed grips from a0: the largest tension at radii
    <= a0 on the stable branch, 1.5 from a0 >= 1.04, the tension at a0 from 0.5 <= a0 < 1.04,
    and 0 (no bound claimed) below 0.5, where JKR has no stable contact but finite mu may.
    """
    if mu <= ELASTIC_MU_MAX:
        return elastic_pull_off(mu, a_start=a0).pull_off
    a_force = jkr_pull_off_point("force")[0]
    a_grips = jkr_pull_off_point("displacement")[0]
    if a0 >= a_force:
        return 1.5
    return float(-jkr_load(a0)) if a0 >= a_grips else 0.0


def upper_bound(mu: float, k: float, a0: float) -> float:
    """max(2/k, pi sigma_0 (a0 + 2 l)^2): see the module docstring (units pi dg R)."""
    sigma0 = 16.0 * mu / (9.0 * math.sqrt(3.0) * math.pi ** (1.0 / 3.0))
    return max(2.0 / k, math.pi * sigma0 * (a0 + 2.0 * tip_zone(mu)) ** 2)


def judge(scene: dict, res) -> str:
    """"ok", "failed: <reason>" or "WRONG: <why>" for one result."""
    if res.status != "ok":
        return f"failed: {res.reason}" if res.reason else "WRONG: failed without a reason"
    p = res.pull_off
    if not math.isfinite(p):
        return "WRONG: ok with a non-finite pull-off"
    lo = relaxed_pull_off(scene["mu"], scene["a0"])
    hi = upper_bound(scene["mu"], scene["k"], scene["a0"])
    # a row that states a larger error (the crack-front model's measured one) is held to it
    stated = res.error_estimate if math.isfinite(res.error_estimate) else 0.0
    slow_rtol, bound_rtol = max(SLOW_RTOL, stated), max(BOUND_RTOL, stated)
    if scene["rate"] == min(RATES) and abs(p / lo - 1.0) > slow_rtol:
        return f"WRONG: slowest rate {p:.5g} != relaxed elastic {lo:.5g}"
    if p < lo * (1.0 - bound_rtol) or p > hi * (1.0 + bound_rtol):
        return f"WRONG: {p:.5g} outside [{lo:.5g}, {hi:.5g}]"
    return "ok"


def classify(scene: dict, res) -> tuple[str, str]:
    """The class of one result (:data:`CLASSES`) and its verdict.

    Parameters
    ----------
    scene : dict
        The scene's fields n, k, rate, a0, mu.
    res : Result
        What :func:`sweep.engine.models.simulate` returned for it.

    Returns
    -------
    (str, str)
        ``("ok", "ok")``, ``("refused", "failed: <reason>")``, ``("failed", "failed:
        <reason>")``, ``("wrong", "WRONG: <why>")`` or, for a result with status "error",
        ``("error", "ERROR: <reason>")``; the bounds are :func:`judge`'s.
    """
    if res.status == "error":
        return "error", f"ERROR: {res.reason or 'internal error without a reason'}"
    if res.status not in ("ok", "failed"):
        return "wrong", f"WRONG: unknown status {res.status!r}"
    verdict = judge(scene, res)
    if verdict.startswith("WRONG"):
        return "wrong", verdict
    if res.status == "ok":
        return "ok", verdict
    return ("refused" if is_physical_refusal(res.reason) else "failed"), verdict


def _row(d, model, res, seconds) -> dict:
    cls, verdict = classify(d, res)
    return dict(d, asked=model, status=res.status, reason=res.reason, pull_off=res.pull_off,
                error_estimate=res.error_estimate, model=res.model_used or model,
                nodes=res.nodes_used,
                lower=relaxed_pull_off(d["mu"], d["a0"]),
                upper=upper_bound(d["mu"], d["k"], d["a0"]),
                cls=cls, verdict=verdict, seconds=seconds)


def run_scene(d: dict, model: str = "bem", numerics=None) -> dict:
    """Run and judge one scene with ``model``: its row.

    An exception escaping :func:`simulate` is caught and recorded as class "error" with its
    traceback (``internal``: whether :func:`sweep.errors.is_internal_error` calls it a bug),
    so that one bug does not end the table.

    Parameters
    ----------
    d : dict
        The scene's fields n, k, rate, a0, mu.
    model : str
        One of :data:`sweep.scene.MODEL_NAMES`.
    numerics : Numerics, optional
        Default: the :data:`PRESET` preset with a :data:`TIME_BUDGET_S` budget.

    Returns
    -------
    dict
        The scene's fields and asked, status, reason, pull_off, model (the one that ran),
        nodes, lower, upper, cls (:data:`CLASSES`), verdict, seconds; an error row also has
        internal and traceback.
    """
    numerics = numerics or Numerics.preset(PRESET, time_budget_s=TIME_BUDGET_S)
    t0 = time.perf_counter()
    try:
        res = simulate(Scene(**d, model=model), numerics)
    except Exception as exc:    # noqa: BLE001 -- recorded, reported, and the run exits 1
        internal = is_internal_error(exc)
        kind = "internal error" if internal else "exception escaped simulate"
        return dict(d, asked=model, status="error", reason=f"{type(exc).__name__}: {exc}",
                    pull_off=math.nan, model=model, nodes=0,
                    lower=math.nan, upper=upper_bound(d["mu"], d["k"], d["a0"]), cls="error",
                    verdict=f"ERROR: {kind}: {type(exc).__name__}: {exc}",
                    internal=internal, traceback=traceback.format_exc(),
                    seconds=time.perf_counter() - t0)
    return _row(d, model, res, time.perf_counter() - t0)


def run(scenes, numerics=None, on_row=None, model: str = "bem") -> list[dict]:
    """Run and judge ``scenes`` (dicts of Scene fields) with ``model``; rows for
    :func:`print_table` (``on_row(row)`` is called as each is done)."""
    rows = []
    for d in scenes:
        rows.append(run_scene(d, model, numerics))
        if on_row is not None:
            on_row(rows[-1])
    return rows


def counts(rows) -> dict:
    """Rows per class (every class of :data:`CLASSES`, zeros included)."""
    out = {c: 0 for c in CLASSES}
    for r in rows:
        out[r["cls"]] += 1
    return out


def random_scenes(count: int, seed: int, floors=None) -> list[dict]:
    """Scenes drawn log-uniformly across the limits Scene declares for n, k, rate, a0 and mu
    (:data:`sweep.scene.AXES`).

    A limit open at 0 (n, k, rate) has no log-uniform law: its lower end is replaced by
    ``floors[name]``, by default the table's smallest value of the axis (n 0.05, k 1e-4,
    rate 1e-4); a closed lower limit (a0, mu) is used as declared.

    Parameters
    ----------
    count : int
        Number of scenes.
    seed : int
        Seed of ``numpy.random.default_rng``: the same seed gives the same scenes.
    floors : dict, optional
        Lower ends of the axes whose declared limit is open at 0.

    Returns
    -------
    list of dict
        Dicts of the Scene fields n, k, rate, a0, mu.
    """
    floors = {"n": min(N_VALUES), "k": min(K_VALUES), "rate": min(RATES), **(floors or {})}
    rng = np.random.default_rng(seed)
    ranges = {}
    for name in ("n", "k", "rate", "a0", "mu"):
        lo, hi = AXES[name].limits
        if lo <= 0.0:
            lo = floors[name]
        ranges[name] = (math.log(lo), math.log(hi))
    return [{name: float(math.exp(rng.uniform(*ranges[name]))) for name in ranges}
            for _ in range(count)]


HEADER = (f"{'mu':>5} {'a0':>4} {'n':>4} {'k':>6} {'rate':>6} {'model':>7} {'class':>7} "
          f"{'pull_off':>9} {'lower':>7} {'upper':>9} {'nodes':>5} {'s':>6}  verdict")


def print_table(rows, out=print, header=True) -> None:
    """Print rows of :func:`run` (one line each; the verdict cut at 110 characters)."""
    if header:
        out(HEADER)
    for r in rows:
        out(f"{r['mu']:5.3g} {r['a0']:4.3g} {r['n']:4.3g} {r['k']:6.3g} {r['rate']:6.3g} "
            f"{r['model']:>7} "
            f"{r['cls']:>7} {r['pull_off']:9.5g} {r['lower']:7.4f} {r['upper']:9.4g} "
            f"{r['nodes']:5d} {r['seconds']:6.1f}  {r['verdict'][:110]}")


def summary_lines(report: dict) -> list[str]:
    """The summary table (markdown): one line per model, the count of each class."""
    cols = [CLASS_TITLES[c] for c in CLASSES]
    lines = ["| model | " + " | ".join(cols) + " | scenes | wall s |",
             "|---" * (len(cols) + 3) + "|"]
    for model, m in report["models"].items():
        c = m["counts"]
        lines.append(f"| {model} | " + " | ".join(str(c[k]) for k in CLASSES)
                     + f" | {len(m['rows'])} | {m['wall_s']:.0f} |")
    return lines


def _scene_str(r) -> str:
    return (f"mu = {r['mu']:.4g}, a0 = {r['a0']:.4g}, n = {r['n']:.4g}, k = {r['k']:.4g}, "
            f"rate = {r['rate']:.4g}")


def reason_key(reason: str) -> str:
    """A failure reason with its numbers replaced by ``#`` and cut at 100 characters: the
    same failure of several scenes gives the same key."""
    return re.sub(r"(?<![A-Za-z_])[-+]?\d+(\.\d+)?([eE][-+]?\d+)?", "#", reason or "")[:100]


def summary_md(report: dict) -> str:
    """``summary.md``: how the table was made, the counts, the reasons of the failed rows
    (grouped, with how many scenes gave each) and every wrong or error row."""
    out = [f"# Extremes: {report['scenes']} scenes of (n, k, rate, a0, mu)", "",
           f"`{report['command']}` on {report['date']} (commit {report['commit']}), "
           f"preset {report['preset']}, time budget {report['time_budget_s']:g} s a scene, "
           f"wall time {report['wall_s']:.0f} s.", "",
           "Classes: ok (finite, inside the physical bounds), physically refused "
           "(sweep.errors.is_physical_refusal), failed (any other reason), wrong (outside the "
           "bounds, non-finite, or failed without a reason), internal error (an exception "
           "escaped simulate).", ""]
    out += summary_lines(report)
    for model, m in report["models"].items():
        groups: dict = {}
        for r in m["rows"]:
            if r["cls"] in ("refused", "failed"):
                groups.setdefault((r["cls"], r["model"], reason_key(r["reason"])), []).append(r)
        if groups:
            out += ["", f"## {model}: reasons of the refused and failed rows", "",
                    "| class | model that ran | scenes | reason (numbers as #) | e.g. |",
                    "|---|---|---|---|---|"]
            for (cls, ran, key), rows in sorted(groups.items(), key=lambda g: -len(g[1])):
                out.append(f"| {cls} | {ran} | {len(rows)} | {key} | {_scene_str(rows[0])} |")
        bad = [r for r in m["rows"] if r["cls"] in ("wrong", "error")]
        if bad:
            out += ["", f"## {model}: wrong and errors", ""]
            out += [f"- {_scene_str(r)} ({r['model']}, {r['seconds']:.1f} s): {r['verdict']}"
                    for r in bad]
    return "\n".join(out) + "\n"


def _git_commit() -> str:
    try:
        return subprocess.run(["git", "rev-parse", "--short", "HEAD"], capture_output=True,
                              text=True, check=True, cwd=Path(__file__).parent).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        return "unknown"


def _main(argv=None) -> int:
    p = argparse.ArgumentParser(prog="python -m sweep.bench.extremes",
                                description="stability at the extremes of the scene space")
    p.add_argument("--quick", action="store_true", help="the covering subset only")
    p.add_argument("--model", nargs="+", choices=MODEL_NAMES, default=list(DEFAULT_MODELS),
                   help="models to run the table with (default: bem auto)")
    p.add_argument("--out", type=Path, default=None,
                   help="directory of extremes.json and summary.md (default results/extremes, "
                   "results/quick/extremes with --quick)")
    p.add_argument("--summary-from", type=Path, metavar="JSON",
                   help="only rewrite summary.md beside JSON, an extremes.json of an earlier run")
    args = p.parse_args(argv)
    if args.summary_from is not None:
        report = json.loads(args.summary_from.read_text())
        (args.summary_from.parent / "summary.md").write_text(summary_md(report))
        print(f"written: {args.summary_from.parent / 'summary.md'}")
        return 0
    out_dir = args.out or Path("results/quick/extremes" if args.quick else "results/extremes")
    out = lambda s: print(s, flush=True)        # noqa: E731
    scenes = QUICK if args.quick else all_scenes()
    argv_shown = " ".join(sys.argv[1:] if argv is None else argv)
    report = dict(command=f"python -m sweep.bench.extremes {argv_shown}".strip(),
                  date=datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC"),
                  commit=_git_commit(), host=platform.node(), cpus=os.cpu_count(),
                  preset=PRESET, time_budget_s=TIME_BUDGET_S, quick=args.quick,
                  scenes=len(scenes), bounds=dict(slow_rtol=SLOW_RTOL, bound_rtol=BOUND_RTOL),
                  models={})
    t_all = time.perf_counter()
    for model in args.model:
        out(f"== model {model}: {len(scenes)} scenes")
        out(HEADER)

        def on_row(row):
            print_table([row], out=out, header=False)
            if row["cls"] == "error":
                print(f"!! {row['verdict']}\n{row['traceback']}", file=sys.stderr, flush=True)

        t0 = time.perf_counter()
        rows = run(scenes, model=model, on_row=on_row)
        report["models"][model] = dict(counts=counts(rows), wall_s=time.perf_counter() - t0,
                                       rows=rows)
        c = report["models"][model]["counts"]
        out(f"{model}: {len(rows)} scenes: " + ", ".join(f"{c[k]} {CLASS_TITLES[k]}"
                                                       for k in CLASSES)
            + f"; {report['models'][model]['wall_s']:.0f} s")
    report["wall_s"] = time.perf_counter() - t_all
    from ..campaign.store import to_jsonable
    out_dir.mkdir(parents=True, exist_ok=True)
    (out_dir / "extremes.json").write_text(json.dumps(to_jsonable(report), indent=1) + "\n")
    (out_dir / "summary.md").write_text(summary_md(report))
    out("")
    for line in summary_lines(report):
        out(line)
    out(f"written: {out_dir / 'extremes.json'}, {out_dir / 'summary.md'}")
    errors = [r for m in report["models"].values() for r in m["rows"] if r["cls"] == "error"]
    wrong = sum(m["counts"]["wrong"] for m in report["models"].values())
    for r in errors:
        print(f"!! ERROR ({r['asked']}; {_scene_str(r)}): {r['verdict']}", file=sys.stderr)
    if errors or wrong:
        print(f"extremes: {wrong} wrong, {len(errors)} errors", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    raise SystemExit(_main())
