r"""Is ``Result.error_estimate`` an estimate of the error? Coverage on a seeded random sample.

Scenes are drawn log-uniformly across the declared limits of the BEM (n, k, mu, a0, rate,
MPL and SLS; :func:`sample`), each is run with the fast, balanced and accurate presets
and with a much finer reference (:data:`REFERENCE`: the accurate preset refined in space,
time, Prony fit and Newton tolerance), and the true relative pull-off error of each preset
against the reference is set beside its ``error_estimate``:

* coverage: the fraction of scenes whose estimate is at least the true error (target >= 0.9);
* looseness: the median of estimate / true error (target <= about 10).

``python -m sweep.bench.error_coverage`` (``make error-coverage``) writes
``results/error_coverage/coverage.json`` (every row and the summary per preset). A scene
whose reference run fails (its time budget) is left out of the summary; the file keeps it.
"""
from __future__ import annotations

import argparse
import json
import math
import sys
import time
from pathlib import Path

import numpy as np

from ..campaign.store import provenance, to_jsonable
from ..engine.models import simulate
from ..engine.resolution import coarser
from ..scene import Numerics, Scene

PRESET_NAMES = ("fast", "balanced", "accurate")
#: the reference: the accurate preset refined in every numerical knob, without the error
#: check's second solve
REFERENCE = dict(band_resolution=60.0, grading=1.03, step=0.025, da_max=0.15, prony_rtol=1e-7,
                 tol=1e-10, max_nodes=5000, pull_off_rtol=0.0)
#: declared ranges of the sample (log-uniform): docs/configs.md, the BEM's Tabor range
RANGES = dict(n=(0.05, 5.0), k=(1e-4, 0.9), mu=(0.01, 100.0), a0=(0.5, 50.0),
              rate=(1e-4, 1e12))
#: the ranges a user declares (docs/configs.md; issue 21's sample): a0 from the Scene's 0.3
USER_RANGES = dict(RANGES, k=(1e-4, 1.0), a0=(0.3, 50.0))


def sample(count: int, seed: int = 0, bem_range: bool = True) -> list[dict]:
    """``count`` scenes (dicts of Scene fields), log-uniform in :data:`RANGES`; a quarter
    SLS. ``bem_range=False``: the sample of the issue that measured the models' holes
    instead (:data:`USER_RANGES`: a0 from 0.3, k up to 1 and a tenth of the scenes elastic,
    k = 1)."""
    ranges = RANGES if bem_range else USER_RANGES
    rng = np.random.default_rng(seed)
    out = []
    for _ in range(count):
        d = {name: float(np.exp(rng.uniform(math.log(lo), math.log(hi))))
             for name, (lo, hi) in ranges.items()}
        d = {name: float(f"{v:.4g}") for name, v in d.items()}
        d["material"] = "sls" if rng.uniform() < 0.25 else "mpl"
        if not bem_range and rng.uniform() < 0.1:
            d["k"] = 1.0
        out.append(d)
    return out


def run_reference(d: dict, budget_s: float = 30.0) -> dict:
    """The reference run of one scene (:data:`REFERENCE`, five times ``budget_s``): the
    ``reference`` entry of a row."""
    ref = simulate(Scene(**d), Numerics.preset("accurate", time_budget_s=5 * budget_s,
                                                **REFERENCE))
    return {"status": ref.status, "reason": ref.reason, "pull_off": ref.pull_off,
            "wall_s": ref.wall_s, "nodes": ref.nodes_used}


def run_scene(d: dict, budget_s: float = 30.0, probe: bool = False) -> dict:
    """Every preset and the reference on one scene: pull-offs, estimates, true errors."""
    row = {"scene": d, "reference": run_reference(d, budget_s)}
    for name in PRESET_NAMES:
        row[name] = run_preset(d, name, row["reference"], budget_s, probe)
    return row


def run_preset(d: dict, name: str, reference: dict, budget_s: float = 30.0,
               probe: bool = False) -> dict:
    """One preset on one scene: its pull-off, estimate and true error against
    ``reference`` (the reference entry of a row: status and pull-off)."""
    out = run_numerics(d, Numerics.preset(name, time_budget_s=budget_s), reference)
    if probe:
        scene = Scene(**d)
        num = Numerics.preset(name, time_budget_s=budget_s, pull_off_rtol=0.0)
        for key, n2 in (("plain", num), ("coarse", coarser(num))):
            r2 = simulate(scene, n2)
            out[f"{key}_pull_off"] = r2.pull_off
            out[f"{key}_wall_s"] = r2.wall_s
    return out


def tolerance_key(rtol: float) -> str:
    """The key of a row's entry for the accuracy request ``rtol`` (``--tolerance``)."""
    return f"rtol_{rtol:g}"


def run_numerics(d: dict, numerics: Numerics, reference: dict) -> dict:
    """``numerics`` on one scene: its pull-off, estimate, the resolution it took and the
    true error against ``reference`` (the reference entry of a row)."""
    res = simulate(Scene(**d), numerics)
    ok = res.ok and reference["status"] == "ok"
    true = abs(res.pull_off / reference["pull_off"] - 1.0) if ok else math.nan
    out = {"status": res.status, "reason": res.reason, "pull_off": res.pull_off,
           "error_estimate": res.error_estimate, "true_error": true,
           "wall_s": res.wall_s, "nodes": res.nodes_used, "spacing": res.spacing,
           "steps": res.steps, "prony_error": res.prony_error, "model": res.model_used,
           "refinements": res.refinements}
    return out


def summarize(rows: list[dict]) -> dict:
    """Coverage and looseness of the estimate per preset and per accuracy request
    (``rtol_*`` entries), over scenes where both it and the reference are ok (a true error
    below 1e-12 counts as covered); for a request also the share of the scenes with a
    reference that it delivered (ok, true error within the tolerance)."""
    out = {}
    requests = sorted({k for r in rows for k in r if k.startswith("rtol_")},
                      key=lambda k: -float(k[5:]))
    for name in (*PRESET_NAMES, *requests):
        pairs = [(r[name]["error_estimate"], r[name]["true_error"]) for r in rows
                 if name in r and r[name]["status"] == "ok" and r["reference"]["status"] == "ok"]
        if not pairs:
            continue
        est = np.array([p[0] for p in pairs], float)
        true = np.array([p[1] for p in pairs], float)
        covered = est >= true
        ratio = est / np.maximum(true, 1e-12)
        out[name] = {"scenes": len(pairs), "coverage": float(np.mean(covered)),
                     "median_looseness": float(np.median(ratio)),
                     "median_true_error": float(np.median(true)),
                     "median_estimate": float(np.median(est)),
                     "max_true_error": float(np.max(true)),
                     "within_pull_off_rtol": float(np.mean(true <= _tolerance(name)))}
        if name.startswith("rtol_"):
            tol = _tolerance(name)
            asked = [r for r in rows if name in r and r["reference"]["status"] == "ok"]
            out[name].update(
                requested=len(asked),
                delivered=float(np.mean([r[name]["status"] == "ok"
                                         and r[name]["true_error"] <= tol for r in asked])),
                refined=int(sum(r[name].get("refinements", 0) > 0 for r in asked)),
                wall_s=float(sum(r[name]["wall_s"] for r in asked)))
    return out


def _tolerance(name: str) -> float:
    return float(name[5:]) if name.startswith("rtol_") else Numerics.preset(name).pull_off_rtol


def _main(argv=None) -> int:
    p = argparse.ArgumentParser(prog="python -m sweep.bench.error_coverage",
                                description="coverage of the per-row error estimate")
    p.add_argument("--scenes", type=int, default=30)
    p.add_argument("--seed", type=int, default=7)
    p.add_argument("--jobs", "-j", type=int, default=2)
    p.add_argument("--budget", type=float, default=30.0,
                   help="time budget of a preset run, s (the reference's: five times it)")
    p.add_argument("--out", default="results/error_coverage")
    p.add_argument("--probe", action="store_true",
                   help="also run each preset without its check and at the check's resolution")
    p.add_argument("--grow", action="store_true",
                   help="keep the rows of OUT/coverage.json (same seed) and run only the "
                        "scenes it lacks (a larger --scenes extends the sample)")
    p.add_argument("--rerun", choices=PRESET_NAMES, action="append", default=[],
                   help="run this preset again on every scene of OUT/coverage.json, the "
                        "references kept (after the preset changed); repeatable")
    p.add_argument("--tolerance", type=float, action="append", default=[],
                   help="ask for this pull-off accuracy (Numerics.for_tolerance) on every "
                        "scene of OUT/coverage.json, the references kept; repeatable")
    args = p.parse_args(argv)
    from joblib import Parallel, delayed

    t0 = time.perf_counter()
    out = Path(args.out)
    rows, wall, commands = [], 0.0, []
    path = out / "coverage.json"
    if (args.rerun or args.tolerance) and not path.exists():
        raise SystemExit(f"error: --rerun/--tolerance: no {path} to take the scenes and "
                         f"references from")
    if (args.grow or args.rerun or args.tolerance) and path.exists():
        old = json.loads(path.read_text())
        if args.grow and old["seed"] != args.seed:
            raise SystemExit(f"error: --grow: {path} has seed {old['seed']}, not {args.seed}")
        # a references file of ``make extrapolation`` (--references) records no wall time
        rows, wall = old["rows"], old.get("wall_s", 0.0)
        commands = old["command"].split(" && ")
    if args.rerun:
        jobs = [(i, name) for i, _ in enumerate(rows) for name in args.rerun]
        for (i, name), got in zip(jobs, Parallel(n_jobs=args.jobs)(
                delayed(run_preset)(rows[i]["scene"], name, rows[i]["reference"], args.budget,
                                    args.probe) for i, name in jobs)):
            rows[i][name] = got
        print(f"reran {', '.join(args.rerun)} on {len(rows)} scenes")
    if args.tolerance:
        jobs = [(i, t) for i, _ in enumerate(rows) for t in args.tolerance]
        for (i, t), got in zip(jobs, Parallel(n_jobs=args.jobs)(
                delayed(run_numerics)(rows[i]["scene"],
                                      Numerics.for_tolerance(t, time_budget_s=args.budget),
                                      rows[i]["reference"]) for i, t in jobs)):
            rows[i][tolerance_key(t)] = got
        print(f"asked for {', '.join(f'{t:g}' for t in args.tolerance)} on {len(rows)} scenes")
    have = [r["scene"] for r in rows]
    scenes = [] if (args.rerun or args.tolerance) else [d for d in sample(args.scenes, args.seed) if d not in have]
    for row in Parallel(n_jobs=args.jobs, return_as="generator_unordered")(
            delayed(run_scene)(d, args.budget, args.probe) for d in scenes):
        rows.append(row)
        s = row["scene"]
        print(f"n={s['n']:<6g} k={s['k']:<8g} mu={s['mu']:<7g} a0={s['a0']:<6g} "
              f"rate={s['rate']:<9.3g} {s['material']:3} ref {row['reference']['status']:6} "
              + " ".join(f"{n}: {row[n]['error_estimate']:.1e}/{row[n]['true_error']:.1e}"
                         for n in PRESET_NAMES), flush=True)
    summary = summarize(rows)
    for name, s in summary.items():
        delivered = (f", delivered {s['delivered']:.2f} of {s['requested']} ({s['refined']} "
                     f"refined, {s['wall_s']:.0f} s)" if "delivered" in s else "")
        print(f"{name:9} {s['scenes']} scenes: coverage {s['coverage']:.2f}, median "
              f"looseness {s['median_looseness']:.3g}, median true error "
              f"{s['median_true_error']:.2g}{delivered}")
    out.mkdir(parents=True, exist_ok=True)
    command = " ".join(["python -m sweep.bench.error_coverage",
                        *(sys.argv[1:] if argv is None else argv)])
    (out / "coverage.json").write_text(json.dumps(to_jsonable(
        {"summary": summary, "rows": rows, "seed": args.seed,
         "wall_s": wall + time.perf_counter() - t0, "reference": REFERENCE,
         "command": " && ".join([*commands, command]), "date": time.strftime("%Y-%m-%d"),
         **provenance()}), indent=1))
    return 0


if __name__ == "__main__":
    raise SystemExit(_main())
