"""Requests of an accuracy where the nodes may hold the crack tip: ``make held-tip``.

Session 50's user test found rows ``ok`` 5-24 % off at low Tabor parameters with a small k
and a broad spectrum or an SLS: the fast mesh held the crack tip at its starting node while
the load fell past the contact's own minimum, and the estimate's coarser solve was held alike
(:func:`sweep.engine.resolution.pinned`, the check that answers it). This scan draws seeded
scenes in that corner (n 1.5-5 or an SLS in a quarter of them, k 1e-4 to 1e-2, mu 1-4, rate
0.1-10), each either a relaxed start (a0 0.6-3) or a test protocol (approach at the
retraction's rate to a preload 0.5-3, a dwell 0-10 tau0 at force), asks each for 3e-2 and
1e-2 (:meth:`sweep.Numerics.for_tolerance`) and compares with the same scene asked for 1e-3.
It reports, per kind and tolerance, the requests missed (an ``ok`` row off by more than its
tolerance), the estimates that do not cover their errors, the rows left unresolved and the
crack tip's travel from the unloading's start to the pull-off in fine spacings (a held tip:
below one). A protocol's retraction starts from the dwell's creeping contact, which the check
leaves out; this scan is what says whether it should not.

Command: ``python -m sweep.bench.held_tip --relaxed 60 --protocols 60 --out FILE``.
"""
from __future__ import annotations

import json
import math
from pathlib import Path

import click
import numpy as np

from ..engine.models import simulate_model
from ..scene import Numerics, Scene

#: the corner of session 50's user test K
RANGES = dict(n=(1.5, 5.0), k=(1e-4, 1e-2), mu=(1.0, 4.0), rate=(0.1, 10.0), a0=(0.6, 3.0),
              preload=(0.5, 3.0), dwell=(0.0, 10.0))
TOLERANCES = (3e-2, 1e-2)
REFERENCE_TOLERANCE = 1e-3


def _log_uniform(rng, lo, hi):
    return float(f"{math.exp(rng.uniform(math.log(lo), math.log(hi))):.4g}")


def scenes(relaxed: int, protocols: int, seed: int = 0) -> list[dict]:
    """``relaxed`` relaxed starts and ``protocols`` test protocols drawn in :data:`RANGES`
    (log-uniform; the dwell uniform; an SLS in a quarter of them), model bem."""
    rng = np.random.default_rng(seed)
    out = []
    for i in range(relaxed + protocols):
        d = {q: _log_uniform(rng, *RANGES[q]) for q in ("n", "k", "mu", "rate")}
        if rng.uniform() < 0.25:
            d["material"] = "sls"
        if i < relaxed:
            d["a0"] = _log_uniform(rng, *RANGES["a0"])
        else:
            d.update(approach_rate=d["rate"], preload=_log_uniform(rng, *RANGES["preload"]),
                     dwell=float(f"{rng.uniform(*RANGES['dwell']):.3g}"))
        out.append({**d, "model": "bem"})
    return out


def travel(res) -> float:
    """The crack tip's travel from the unloading's start (a protocol's: its retraction's) to
    the pull-off, in fine spacings (NaN where unknown)."""
    tr = res.trajectory
    if not res.ok or not res.spacing > 0.0:
        return math.nan
    if "phase" in tr and (np.asarray(tr["phase"]) == 2).any():
        start = float(np.asarray(tr["a"])[np.asarray(tr["phase"]) == 2][0])
    else:
        start = res.a0_result
    return (start - res.a_pulloff) / res.spacing


def scan(relaxed: int = 60, protocols: int = 60, seed: int = 0, progress=print) -> dict:
    """Every scene of :func:`scenes` at each of :data:`TOLERANCES` and at the reference's
    tolerance; the rows and a summary per kind (relaxed, protocol) and tolerance."""
    rows = []
    for i, d in enumerate(scenes(relaxed, protocols, seed)):
        scene = Scene(**d)
        ref = simulate_model(scene, "bem", Numerics.for_tolerance(REFERENCE_TOLERANCE))
        row = {"scene": d, "kind": "protocol" if scene.protocol() is not None else "relaxed",
               "reference": {"status": ref.status, "pull_off": ref.pull_off,
                             "error_estimate": ref.error_estimate, "wall_s": ref.wall_s}}
        for tol in TOLERANCES:
            res = simulate_model(scene, "bem", Numerics.for_tolerance(tol))
            err = (abs(res.pull_off - ref.pull_off) / abs(ref.pull_off)
                   if res.ok and ref.ok else math.nan)
            row[f"{tol:g}"] = {"status": res.status, "reason": res.reason[:200],
                               "pull_off": res.pull_off, "error_estimate": res.error_estimate,
                               "error": err, "travel": travel(res), "wall_s": res.wall_s,
                               "refinements": res.refinements}
        rows.append(row)
        progress(f"held_tip {i + 1}: {row['kind']} {d}: reference {ref.status}; "
                 + ", ".join(f"{tol:g}: {row[f'{tol:g}']['status']} error "
                             f"{row[f'{tol:g}']['error']:.2g}" for tol in TOLERANCES))
    return {"kind": "held_tip", "seed": seed, "ranges": RANGES, "tolerances": TOLERANCES,
            "reference_tolerance": REFERENCE_TOLERANCE, "summary": summarize(rows),
            "rows": rows}


def summarize(rows: list[dict]) -> dict:
    """Per kind and tolerance: scenes with a reference, requests ok, missed, estimates not
    covering, unresolved, the worst error, the least travel and the rows held (travel < 1)."""
    out = {}
    for kind in ("relaxed", "protocol"):
        for tol in TOLERANCES:
            key = f"{tol:g}"
            sel = [r for r in rows if r["kind"] == kind and r["reference"]["status"] == "ok"]
            ok = [r[key] for r in sel if r[key]["status"] == "ok"]
            errors = [q["error"] for q in ok]
            travels = [q["travel"] for q in ok if math.isfinite(q["travel"])]
            out[f"{kind} {key}"] = {
                "scenes": len(sel), "ok": len(ok),
                "missed": sum(e > tol for e in errors),
                "not_covered": sum(q["error"] > q["error_estimate"] for q in ok),
                "unresolved": sum(r[key]["reason"].startswith("unresolved") for r in sel),
                "worst_error": max(errors, default=math.nan),
                "least_travel": min(travels, default=math.nan),
                "held": sum(t < 1.0 for t in travels),
                "wall_s": sum(r[key]["wall_s"] for r in sel)}
    return out


@click.command()
@click.option("--relaxed", type=click.IntRange(0), default=60, show_default=True)
@click.option("--protocols", type=click.IntRange(0), default=60, show_default=True)
@click.option("--seed", type=int, default=0, show_default=True)
@click.option("--out", default="results/error_coverage/held_tip.json", show_default=True)
def main(relaxed, protocols, seed, out):
    """Requests of 3e-2 and 1e-2 where the nodes may hold the crack tip, against 1e-3."""
    report = scan(relaxed, protocols, seed, progress=lambda m: click.echo(m, err=True))
    Path(out).parent.mkdir(parents=True, exist_ok=True)
    Path(out).write_text(json.dumps(report, indent=1, default=float))
    for key, s in report["summary"].items():
        click.echo(f"{key}: {s['ok']} ok of {s['scenes']}, missed {s['missed']}, not covered "
                   f"{s['not_covered']}, unresolved {s['unresolved']}, worst {s['worst_error']:.2g}"
                   f", least travel {s['least_travel']:.2g} spacings, held {s['held']}")


if __name__ == "__main__":
    main()
