r"""Is the error estimate's pair an extrapolation pair? (issue 33 item 2, ``make extrapolation``)

Every BEM row solves its scene twice: at its resolution (pull-off P_h) and at half of it in
space and time (P_2h, the estimate's solve, :func:`sweep.engine.resolution.estimate_error`).
For a discretization of order p, Richardson's extrapolation

    P_x = P_h + (P_h - P_2h) / (2^p - 1)

would be more accurate than P_h, for free. Whether it is, and whether the order is the same
from scene to scene, is measured here on the error-coverage sample's scenes, whose converged
references ``make error-coverage`` keeps (results/error_coverage/coverage.json, the scenes
whose reference run succeeded): per preset, each scene's P_h, P_2h and a third solve at a
quarter of the resolution, P_4h (the same solve routine as the estimate's, its numerics
:func:`sweep.engine.resolution.coarser` twice), then

* the true relative errors of P_h and of P_x (p = 2, the order the estimate assumes; and
  with the order each scene's three solves show, p = log2((P_2h - P_4h)/(P_h - P_2h)));
* the fraction of scenes whose P_x is nearer the reference than P_h;
* the observed orders;
* the coverage of the estimates: the pair's |P_h - P_2h|/P_h + Prony error for P_h, and the
  size of the correction, |P_x - P_h|/P_h + Prony error, for P_x; the three-resolution
  estimate max(|P_h - P_2h|, |P_2h - P_4h|/4)/P_h + Prony error for P_h, always; and the
  row's own ``error_estimate`` (the engine's: the pair, with the third solve where the
  pair's change is small enough to have crossed the limit,
  :data:`sweep.engine.resolution.CROSSING_GATE`).

Written to ``results/error_coverage/extrapolation.json`` (every scene's solves and the
summary), a table on stdout.

A second, independent sample (a seed other than error-coverage's, so that what was chosen
on the first is checked on the second) gets its references with ``--references COUNT --seed
SEED --coverage PATH`` (the sampler and the reference numerics of
:mod:`sweep.bench.error_coverage`, the references alone, written to PATH as a coverage file)
before the run: ``make extrapolation`` does both samples.

What the crossing check costs on a campaign: ``--crossing-cost CONFIG [--every K]`` runs
every K-th scene of the config in one process, each with and without the check
(:data:`sweep.engine.resolution.CROSSING_GATE` set to 0), alternating which goes first, and
prints the two walls, their ratio and how many estimates the check raised
(:func:`crossing_cost`).

``python -m sweep.bench.extrapolation [--coverage PATH] [--out PATH] [-j N]``
``python -m sweep.bench.extrapolation --references 40 --seed 11 --coverage PATH [-j N]``
``python -m sweep.bench.extrapolation --crossing-cost configs/v_vs_r.yaml [--every K]``
"""
from __future__ import annotations

import argparse
import contextlib
import json
import math
import sys
import time
from pathlib import Path

import numpy as np

from ..campaign.store import provenance, to_jsonable

PRESET_NAMES = ("fast", "balanced", "accurate")
COVERAGE = Path("results") / "error_coverage" / "coverage.json"
OUT = Path("results") / "error_coverage" / "extrapolation.json"


@contextlib.contextmanager
def _pairs(got: list):
    """While inside, every BEM error estimate appends (band resolution, ok, pull-off) of its
    coarser solve to ``got``, and of a third solve at a quarter of the resolution (the same
    solve routine, :func:`sweep.engine.resolution.coarser` twice; the crossing check's own
    where it ran)."""
    from ..engine import bem, resolution, tip_following

    original = resolution.estimate_error

    def estimate(res, length, solve):
        def recorded(numerics):
            out = solve(numerics)
            got.append((numerics.band_resolution, bool(out.ok), float(out.pull_off)))
            return out
        original(res, length, recorded)
        # the quarter-resolution solve, unless the estimate's crossing check made it
        if res.ok and len(got) == 1 and got[0][1] and res.numerics.pull_off_rtol > 0:
            recorded(resolution.coarser(resolution.coarser(res.numerics, 2.0), 2.0))

    bem.estimate_error = tip_following.estimate_error = estimate
    try:
        yield
    finally:
        bem.estimate_error = tip_following.estimate_error = original


def run_scene(scene: dict, reference: float, preset: str, budget_s: float = 60.0) -> dict:
    """One scene at one preset: P_h, its estimate and Prony error, and the coarser solves."""
    from ..engine.models import simulate
    from ..scene import Numerics, Scene

    got: list = []
    with _pairs(got):
        res = simulate(Scene(**scene), Numerics.preset(preset, time_budget_s=budget_s))
    return {"scene": scene, "preset": preset, "reference": reference, "status": res.status,
            "model": res.model_used, "pull_off": res.pull_off,
            "error_estimate": res.error_estimate, "prony_error": res.prony_error,
            "coarse": got}


def reference_row(scene: dict, budget_s: float = 30.0) -> dict:
    """The reference run of one scene (:func:`sweep.bench.error_coverage.run_reference`), as
    a row of a coverage file."""
    from .error_coverage import run_reference

    return {"scene": scene, "reference": run_reference(scene, budget_s)}


def crossing_cost(config: str, every: int = 1) -> dict:
    """Wall time of every ``every``-th scene of the sweep ``config`` with the crossing check
    and without it (the gate 0), in this process, the order alternating scene by scene (the
    first three scenes run once before, untimed), and the estimates the check raised."""
    from ..campaign.config import load_config
    from ..engine import resolution
    from ..engine.models import simulate

    cfg = load_config(config)
    scenes, numerics = cfg.scenes()[::every], cfg.numerics
    for scene in scenes[:3]:
        simulate(scene, numerics)
    gate = resolution.CROSSING_GATE
    wall, raised = {gate: 0.0, 0.0: 0.0}, 0
    try:
        for i, scene in enumerate(scenes):
            estimate = {}
            for g in ((gate, 0.0) if i % 2 else (0.0, gate)):
                resolution.CROSSING_GATE = g
                t0 = time.perf_counter()
                estimate[g] = simulate(scene, numerics).error_estimate
                wall[g] += time.perf_counter() - t0
            raised += bool(estimate[gate] > estimate[0.0] * (1.0 + 1e-9))
    finally:
        resolution.CROSSING_GATE = gate
    return {"config": str(config), "every": every, "scenes": len(scenes),
            "wall_with_s": wall[gate], "wall_without_s": wall[0.0],
            "ratio": wall[gate] / wall[0.0], "estimates_raised": raised}


def _observed_order(p_h, p_2h, p_4h) -> float:
    if p_h == p_2h or p_2h == p_4h:
        return math.nan
    q = (p_2h - p_4h) / (p_h - p_2h)
    return math.log2(q) if q > 0 else math.nan


def summarize(rows: list[dict]) -> dict:
    """Per preset (module docstring): median errors, the fraction improved, the observed
    orders, and the estimates' coverage (estimate >= true error) and median looseness."""
    out = {}
    for preset in PRESET_NAMES:
        use = [r for r in rows if r["preset"] == preset and r["status"] == "ok"
               and len(r["coarse"]) >= 2 and r["coarse"][0][1] and r["coarse"][1][1]
               and r["coarse"][0][0] != r["coarse"][1][0]]
        if not use:
            continue
        e_h, e_x2, e_xp, est, est_x, est_3, orders, engine = ([] for _ in range(8))
        for r in use:
            p_h, ref, prony = r["pull_off"], r["reference"], r["prony_error"]
            p_2h, p_4h = r["coarse"][0][2], r["coarse"][1][2]
            c1, c2 = abs(p_h - p_2h) / abs(p_h), abs(p_2h - p_4h) / abs(p_h)
            p = _observed_order(p_h, p_2h, p_4h)
            orders.append(p)
            x2 = p_h + (p_h - p_2h) / 3.0
            xp = p_h + (p_h - p_2h) / (2.0 ** p - 1.0) if p > 0.25 else p_h
            e_h.append(abs(p_h - ref) / abs(ref))
            e_x2.append(abs(x2 - ref) / abs(ref))
            e_xp.append(abs(xp - ref) / abs(ref))
            est.append(c1 + prony)
            est_x.append(c1 / 3.0 + prony)
            est_3.append(max(c1, c2 / 4.0) + prony)
            engine.append(r["error_estimate"])
        e_h, e_x2, e_xp, est, est_x, est_3, orders, engine = map(
            np.asarray, (e_h, e_x2, e_xp, est, est_x, est_3, orders, engine))
        tiny = 1e-16

        def cover(e, x):
            return {"coverage": float(np.mean(x >= e)),
                    "median_looseness": float(np.median(x / np.maximum(e, tiny)))}

        finite = orders[np.isfinite(orders)]
        out[preset] = {
            "scenes": len(use),
            "median_error": float(np.median(e_h)),
            "median_error_extrapolated_p2": float(np.median(e_x2)),
            "median_error_extrapolated_observed_p": float(np.median(e_xp)),
            "improved_p2": float(np.mean(e_x2 < e_h)),
            "worse_p2_by_2x": float(np.mean(e_x2 > 2.0 * e_h)),
            "observed_order": {"median": float(np.median(finite)) if finite.size else None,
                               "quartiles": ([float(x) for x in np.percentile(finite, [25, 75])]
                                             if finite.size else None),
                               "undefined": int(orders.size - finite.size)},
            "estimate_pair": cover(e_h, est),
            "estimate_extrapolated": cover(e_x2, est_x),
            "estimate_three_resolutions": cover(e_h, est_3),
            "estimate_engine": cover(e_h, engine),
        }
    return out


def _main(argv=None) -> int:
    p = argparse.ArgumentParser(prog="python -m sweep.bench.extrapolation",
                                description=__doc__.split("\n")[0])
    p.add_argument("--coverage", default=str(COVERAGE),
                   help="the error-coverage file whose scenes and references to use")
    p.add_argument("--out", default=str(OUT))
    p.add_argument("--jobs", "-j", type=int, default=2)
    p.add_argument("--references", type=int, default=0, metavar="COUNT",
                   help="draw COUNT scenes (error-coverage's sampler, --seed) and write their "
                        "references to --coverage instead")
    p.add_argument("--seed", type=int, default=11)
    p.add_argument("--crossing-cost", metavar="CONFIG",
                   help="time CONFIG's scenes with and without the crossing check instead")
    p.add_argument("--every", type=int, default=1, help="with --crossing-cost: every K-th scene")
    args = p.parse_args(argv)
    if args.crossing_cost:
        c = crossing_cost(args.crossing_cost, args.every)
        print(f"{c['config']}: {c['scenes']} scenes, with the crossing check "
              f"{c['wall_with_s']:.1f} s, without {c['wall_without_s']:.1f} s, ratio "
              f"{c['ratio']:.3f}; {c['estimates_raised']} estimates raised")
        return 0
    from joblib import Parallel, delayed

    path = Path(args.coverage)
    if args.references:
        from .error_coverage import sample
        t0 = time.perf_counter()
        rows = Parallel(n_jobs=args.jobs)(delayed(reference_row)(d)
                                          for d in sample(args.references, args.seed))
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(json.dumps(to_jsonable(
            {"what": "references of a seeded sample (sweep.bench.extrapolation)",
             "seed": args.seed, "rows": rows, "wall_s": time.perf_counter() - t0,
             "command": "python -m sweep.bench.extrapolation " + " ".join(
                 sys.argv[1:] if argv is None else argv), **provenance()}), indent=1))
        ok = sum(r["reference"]["status"] == "ok" for r in rows)
        print(f"wrote {path}: {ok} of {len(rows)} references ok")
        return 0
    if not path.exists():
        raise SystemExit(f"error: --coverage: no {path} (make error-coverage writes it)")
    t0 = time.perf_counter()
    coverage = json.loads(path.read_text())
    jobs = [(row["scene"], row["reference"]["pull_off"], preset)
            for row in coverage["rows"] if row["reference"]["status"] == "ok"
            for preset in PRESET_NAMES]
    rows = Parallel(n_jobs=args.jobs)(delayed(run_scene)(*job) for job in jobs)
    summary = summarize(rows)
    for preset, s in summary.items():
        o = s["observed_order"]
        print(f"{preset:9s} {s['scenes']} scenes: median error {s['median_error']:.2g}, "
              f"extrapolated (p = 2) {s['median_error_extrapolated_p2']:.2g} (nearer in "
              f"{s['improved_p2']:.0%}, 2x worse in {s['worse_p2_by_2x']:.0%}), observed order "
              f"median {o['median']:.2f}, quartiles {o['quartiles'][0]:.2f}-{o['quartiles'][1]:.2f}")
        for key in ("estimate_pair", "estimate_extrapolated", "estimate_three_resolutions",
                    "estimate_engine"):
            print(f"    {key:28s} coverage {s[key]['coverage']:.3f}, median looseness "
                  f"{s[key]['median_looseness']:.2g}")
    out = Path(args.out)
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(json.dumps(to_jsonable(
        {"what": "the error estimate's pair as an extrapolation pair (issue 33 item 2)",
         "command": "make extrapolation", "coverage_file": str(path),
         "coverage_commit": coverage.get("git_commit"), "summary": summary, "rows": rows,
         "wall_s": time.perf_counter() - t0, "date": time.strftime("%Y-%m-%d"),
         **provenance()}), indent=1))
    print(f"wrote {out}")
    return 0


if __name__ == "__main__":
    sys.exit(_main())
