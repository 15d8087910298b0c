"""Does a test protocol's ``hysteresis_error`` cover its hysteresis energy's true error?
(``make hysteresis-coverage``; docs/design.md, "The hysteresis energy's error").

A seeded sample of protocols (:func:`sample`: n 0.2-1.5, k 0.01-0.5, mu 0.03-5, rates and
approach rates 0.1-1000, preloads 0.3-10, dwells 0, 1 or 100 tau0 held at force or depth),
each run at the fast and balanced presets and against a finer run (:data:`REFERENCE`). Per
row: the hysteresis energy, its ``hysteresis_error``, its true error against the reference,
and the part of the estimate the coarser solve's change gives alone (``pair``: what the
estimate was before the trapezoid's term). Written to
``results/protocol/hysteresis_coverage.json`` with a summary on stdout: the rows covered,
the median and largest looseness (estimate over true error), with and without the
trapezoid's term.

``python -m sweep.bench.hysteresis_coverage [--seed S] [--scenes N] [--out PATH]``
"""
from __future__ import annotations

import argparse
import json
import math
import sys
import time
from pathlib import Path

import numpy as np

from ..engine.postprocess import cycle_end, work_quadrature_error
from ..engine.resolution import ESTIMATE_ORDER
from ..scene import Numerics, Scene
from ..engine.models import simulate

#: the reference: the accurate preset's tolerances, finer in space and time (at mu 0.03-0.07
#: the same at step 0.05 h0 and da_max 0.2 within 8e-4)
REFERENCE = Numerics.preset("accurate", pull_off_rtol=0.0, band_resolution=48.0, step=0.1,
                            da_max=0.4)
PRESETS = ("fast", "balanced")
OUT = Path("results/protocol/hysteresis_coverage.json")


def sample(seed: int = 1, scenes: int = 10) -> list[dict]:
    """The seeded sample's scenes (dimensionless fields of :class:`sweep.Scene`)."""
    rng = np.random.default_rng(seed)
    out = []
    for _ in range(scenes):
        out.append(dict(n=float(rng.uniform(0.2, 1.5)), k=float(10 ** rng.uniform(-2, -0.3)),
                        mu=float(10 ** rng.uniform(-1.5, 0.7)),
                        rate=float(10 ** rng.uniform(-1, 3)),
                        approach_rate=float(10 ** rng.uniform(-1, 3)),
                        preload=float(10 ** rng.uniform(-0.5, 1)),
                        dwell=float(rng.choice([0.0, 1.0, 100.0])),
                        dwell_hold=str(rng.choice(["force", "depth"]))))
    return out


def row(fields: dict) -> dict:
    """One scene at each preset against the reference."""
    ref = simulate(Scene(**fields), REFERENCE)
    out = {"scene": fields, "reference": ref.hysteresis_energy if ref.ok else None,
           "reference_status": ref.status}
    for preset in PRESETS:
        res = simulate(Scene(**fields), Numerics.preset(preset))
        entry = {"status": res.status, "hysteresis_energy": res.hysteresis_energy,
                 "hysteresis_error": res.hysteresis_error, "pull_off_estimate": res.error_estimate,
                 "steps": res.steps, "true_error": None, "pair": None}
        if res.ok and ref.ok and math.isfinite(res.hysteresis_error):
            entry["true_error"] = abs(res.hysteresis_energy / ref.hysteresis_energy - 1.0)
            entry["pair"] = res.hysteresis_error - (
                work_quadrature_error(res.trajectory, cycle_end(res))
                / (2.0 ** ESTIMATE_ORDER - 1.0))
        out[preset] = entry
    return out


def summary(rows: list[dict]) -> dict:
    """Per preset: rows compared, covered by the estimate and by the pair alone, and the
    estimate's looseness (estimate / true error: median, largest)."""
    out = {}
    for preset in PRESETS:
        done = [r[preset] for r in rows if r[preset]["true_error"] is not None]
        loose = [e["hysteresis_error"] / e["true_error"] for e in done if e["true_error"] > 0]
        out[preset] = {
            "compared": len(done),
            "covered": sum(e["hysteresis_error"] >= e["true_error"] for e in done),
            "covered_by_the_pair_alone": sum(e["pair"] >= e["true_error"] for e in done),
            "looseness_median": float(np.median(loose)) if loose else None,
            "looseness_max": float(np.max(loose)) if loose else None,
            "true_error_max": max((e["true_error"] for e in done), default=None)}
    return out


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="python -m sweep.bench.hysteresis_coverage",
                                     description=__doc__.splitlines()[0])
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--scenes", type=int, default=10)
    parser.add_argument("--out", type=Path, default=OUT)
    args = parser.parse_args(argv)
    t0 = time.perf_counter()
    rows = []
    for i, fields in enumerate(sample(args.seed, args.scenes)):
        rows.append(row(fields))
        e = rows[-1]["balanced"]
        print(f"{i + 1}/{args.scenes}: mu {fields['mu']:.3g}, balanced: estimate "
              f"{e['hysteresis_error']:.2g}, true {e['true_error']}", flush=True)
    data = {"what": "a protocol's hysteresis_error against its true error (a finer run)",
            "command": "make hysteresis-coverage", "seed": args.seed,
            "reference": REFERENCE.to_dict(), "summary": summary(rows), "rows": rows,
            "wall_s": time.perf_counter() - t0}
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(json.dumps(data, indent=1, default=float) + "\n")
    print(json.dumps(data["summary"], indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
