r"""How far the cheaper models are from the BEM: the measurement the model chooser reads.

A seeded random sample at each Tabor parameter of :data:`MUS` (n, k, rate, a0 drawn
log-uniformly in :data:`RANGES`) is run with the BEM (balanced preset, on the mesh the engine
picks: graded or tip-following) and with the crack-front model and the PB estimate; each row
keeps the relative pull-off differences ``crack / BEM - 1`` and ``pb / BEM - 1`` beside the
BEM's own error estimate.

``python -m sweep.bench.model_errors`` (``make model-errors``) writes the rows, per mu the
largest difference, and the fitted envelope of the difference over mu and the amplification
(:func:`fit_envelope`) to ``sweep/engine/model_errors.json`` (package data:
:mod:`sweep.engine.models` reads it to choose a model and to state the chosen model's error).
``--refit`` fits the rows of an existing file again without running anything.
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
from ..engine.crack_front import simulate_crack
from ..engine.models import amplification, simulate, simulate_pb
from ..scene import Numerics, Scene

#: Tabor parameters of the measurement (the crack-front model is the mu -> infinity limit)
MUS = (2.0, 3.24, 6.0, 10.0, 20.0, 40.0, 100.0)
#: log-uniform ranges of the other axes (a0 up to 6: the crack-front model's finite-size
#: error is largest at small contacts, and the BEM's cost at high mu grows with a0)
RANGES = dict(n=(0.1, 3.0), k=(1e-3, 0.5), rate=(1e-2, 1e8), a0=(0.6, 6.0))
OUT = Path(__file__).resolve().parents[1] / "engine" / "model_errors.json"


def sample(per_mu: int, seed: int = 0) -> list[dict]:
    """``per_mu`` scenes at each mu of :data:`MUS` (dicts of Scene fields)."""
    rng = np.random.default_rng(seed)
    out = []
    for mu in MUS:
        for _ in range(per_mu):
            d = {name: float(f"{np.exp(rng.uniform(math.log(lo), math.log(hi))):.4g}")
                 for name, (lo, hi) in RANGES.items()}
            out.append(dict(d, mu=mu))
    return out


def run_scene(d: dict, budget_s: float) -> dict:
    """The BEM, the crack-front model and the PB estimate on one scene."""
    scene = Scene(**d)
    bem = simulate(scene, Numerics.preset("balanced", time_budget_s=budget_s))
    crack, pb = simulate_crack(scene), simulate_pb(scene)
    row = {"scene": d, "bem_status": bem.status, "bem_reason": bem.reason,
           "bem_pull_off": bem.pull_off, "bem_error_estimate": bem.error_estimate,
           "bem_wall_s": bem.wall_s, "crack_status": crack.status,
           "crack_reason": crack.reason, "crack_pull_off": crack.pull_off,
           "crack_wall_s": crack.wall_s, "pb_pull_off": pb.pull_off}
    for name in ("crack", "pb"):
        row[f"{name}_vs_bem"] = (row[f"{name}_pull_off"] / bem.pull_off - 1.0
                                 if bem.ok and math.isfinite(row[f"{name}_pull_off"])
                                 else math.nan)
    return row


def _diff(row: dict, name: str) -> float:
    """``row[name_vs_bem]``, NaN where missing (JSON stores NaN as null)."""
    d = row.get(f"{name}_vs_bem")
    return math.nan if d is None else float(d)


def bins(rows: list[dict], name: str = "crack") -> list[dict]:
    """Per mu: scenes compared, the largest and the median |model / BEM - 1|, and the
    largest BEM error estimate among them (for the report)."""
    out = []
    for mu in sorted({r["scene"]["mu"] for r in rows}):
        d = [abs(_diff(r, name)) for r in rows
             if r["scene"]["mu"] == mu and math.isfinite(_diff(r, name))]
        e = [r["bem_error_estimate"] for r in rows
             if r["scene"]["mu"] == mu and math.isfinite(_diff(r, name))]
        if d:
            out.append({"mu": mu, "scenes": len(d), "max": max(d),
                        "median": float(np.median(d)), "bem_error_estimate_max": max(e)})
    return out


def fit_envelope(rows: list[dict], name: str = "crack") -> dict:
    """The error model of ``name`` against the BEM: a least-squares fit
    ``log|d| = b0 + b_mu log mu + b_amp log A`` (A: :func:`amplification` of the model's own
    pull-off) raised by ``shift``, the largest residual, so that every measured difference
    lies on or under it (the envelope). :func:`sweep.engine.models.measured_error` evaluates
    it."""
    pts = [(r["scene"]["mu"], amplification(r[f"{name}_pull_off"]), abs(_diff(r, name)))
           for r in rows if math.isfinite(_diff(r, name)) and _diff(r, name) != 0]
    mu, amp, d = (np.array(c, float) for c in zip(*pts))
    x = np.column_stack([np.ones(mu.size), np.log(mu), np.log(amp)])
    b, *_ = np.linalg.lstsq(x, np.log(d), rcond=None)
    resid = np.log(d) - x @ b
    return {"b0": float(b[0]), "b_mu": float(b[1]), "b_amp": float(b[2]),
            "shift": float(resid.max()), "median_residual": float(np.median(resid)),
            "scenes": int(mu.size), "mu_range": [float(mu.min()), float(mu.max())],
            "amplification_range": [float(amp.min()), float(amp.max())]}


def _main(argv=None) -> int:
    p = argparse.ArgumentParser(prog="python -m sweep.bench.model_errors",
                                description="the cheaper models against the BEM")
    p.add_argument("--per-mu", type=int, default=6)
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--jobs", "-j", type=int, default=2)
    p.add_argument("--budget", type=float, default=60.0, help="BEM time budget a scene, s")
    p.add_argument("--out", default=str(OUT))
    p.add_argument("--refit", metavar="JSON", help="fit the rows of this file again, run nothing")
    args = p.parse_args(argv)
    if args.refit:
        doc = json.loads(Path(args.refit).read_text())
        for name in ("crack", "pb"):
            doc[name] = {"fit": fit_envelope(doc["rows"], name), "bins": bins(doc["rows"], name)}
        Path(args.out).write_text(json.dumps(to_jsonable(doc), indent=1))
        print(json.dumps({name: doc[name]["fit"] for name in ("crack", "pb")}, indent=1))
        return 0
    from joblib import Parallel, delayed

    t0 = time.perf_counter()
    rows = []
    for row in Parallel(n_jobs=args.jobs, return_as="generator")(
            delayed(run_scene)(d, args.budget) for d in sample(args.per_mu, args.seed)):
        rows.append(row)
        s = row["scene"]
        print(f"mu={s['mu']:<5g} n={s['n']:<6g} k={s['k']:<7g} a0={s['a0']:<6g} "
              f"rate={s['rate']:<9.3g} BEM {row['bem_status']:6} {row['bem_pull_off']:.5g} "
              f"({row['bem_wall_s']:.1f} s) crack {100 * row['crack_vs_bem']:+.2f} % "
              f"pb {100 * row['pb_vs_bem']:+.1f} %  {row['bem_reason'][:60]}", flush=True)
    doc = {name: {"fit": fit_envelope(rows, name), "bins": bins(rows, name)}
           for name in ("crack", "pb")}
    doc.update({"rows": rows,
           "command": " ".join(["python -m sweep.bench.model_errors",
                                *(sys.argv[1:] if argv is None else argv)]),
           "seed": args.seed, "per_mu": args.per_mu, "wall_s": time.perf_counter() - t0,
           "date": time.strftime("%Y-%m-%d"), **provenance()})
    for e in doc["crack"]["bins"]:
        print(f"crack-front model, mu = {e['mu']:g}: {e['scenes']} scenes, max |diff| "
              f"{e['max']:.3g}, median {e['median']:.3g}")
    Path(args.out).write_text(json.dumps(to_jsonable(doc), indent=1))
    return 0


if __name__ == "__main__":
    raise SystemExit(_main())
