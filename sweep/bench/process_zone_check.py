"""The BEM's process zone against the crack-front model, and what it costs (``make pz-check``).

For each case of :data:`CASES` (an elastic bulk and two viscoelastic materials at mu = 5,
the Gent-Schultz process zone pz_v0 = 1 a_ref/tau0, xi = 0.5) and each rate, the pull-off
with and without the process zone from the BEM (balanced preset, both on the graded mesh
and by the time march: :func:`sweep.engine.bem.simulate`, not the tip-following mesh or the
elastic branch ``model: bem`` would pick without a process zone) and from the crack-front
model, their amplifications P(pz)/P(none), and the BEM's wall time with the process zone
over the same scene's without it: one process, the kernels compiled first, each scene run
once before it is timed (the relaxed start is cached per mesh: the first of the pair would
pay for both), then the two timed in alternation, :data:`REPEATS` times each, the fastest.

The cost the issue bounds is measured on the bench scenes (``make bench``'s vs-numpy and
trade-off scenes, :func:`bench_cost`): each LJ scene, then the same scene with the
Gent-Schultz process zone whose pz_v0 is :data:`BENCH_SPEED_MULTIPLES` times the LJ scene's
crack speed at pull-off (1: the zone doubles the work of adhesion at the crack's own speed,
a strong one; 10: a moderate one), timed in the same way, and the crack-front model's wall
time on the same scene with the process zone (the fastest of :data:`REPEATS` runs after one
untimed). Written to
``results/process_zone/check.json`` with a table on stdout.

``python -m sweep.bench.process_zone_check [--out PATH]``
"""
from __future__ import annotations

import dataclasses
import sys
import time
from pathlib import Path

import numpy as np

from ..campaign.store import provenance
from ..engine import bem
from ..engine.models import simulate
from ..engine.process_zone import opening_rate_scale
from ..scene import Numerics, Scene
from . import measurement_main
from .tradeoff import TRADEOFF_SCENES, VS_NUMPY_SCENES

MU, A0 = 5.0, 1.5
PZ = dict(pz_law="gent-schultz", pz_v0=1.0, pz_xi=0.5)
#: (name, material fields, rates)
CASES = (("elastic", dict(n=0.5, k=1.0), (0.1, 1.0, 10.0, 100.0)),
         ("MPL n 0.5 k 0.1", dict(n=0.5, k=0.1), (1.0, 10.0, 100.0)),
         ("SLS k 0.2", dict(material="sls", n=0.5, k=0.2), (1.0, 10.0)))
OUT = Path("results") / "process_zone" / "check.json"
#: timed runs of each scene (after the untimed first), alternated; the fastest is kept (on a
#: shared VM the median of three moved these ratios by 10-30 % between runs)
REPEATS = 7
#: the bench scenes' process zones: pz_v0 = these multiples of the LJ scene's crack speed
BENCH_SPEED_MULTIPLES = (1.0, 10.0)
#: the bench scenes' process-zone exponent
BENCH_XI = 0.5


def _wall(scene: Scene, run=bem.simulate):
    """``run(scene)`` at the balanced preset: (result, wall time in s)."""
    t0 = time.perf_counter()
    res = run(scene, Numerics.preset("balanced"))
    return res, time.perf_counter() - t0


def bench_cost() -> list[dict]:
    """The BEM's wall time with a process zone over without it on the bench scenes (module
    docstring): one row per scene and pz_v0 multiple."""
    rows = []
    for name, fields in {**VS_NUMPY_SCENES, **TRADEOFF_SCENES}.items():
        plain = Scene(model="bem", **fields)
        lj, _ = _wall(plain)
        for multiple in BENCH_SPEED_MULTIPLES:
            scene = dataclasses.replace(plain, pz_law="gent-schultz", pz_xi=BENCH_XI,
                                        pz_v0=float(multiple * lj.crack_speed))
            res, _ = _wall(scene)
            timed = [(_wall(scene)[1], _wall(plain)[1]) for _ in range(REPEATS)]
            w_pz, w = (float(np.min(x)) for x in zip(*timed))
            crack = dataclasses.replace(scene, model="crack")
            _wall(crack, simulate)                              # its law's spectrum cached
            w_crack = float(np.min([_wall(crack, simulate)[1] for _ in range(REPEATS)]))
            row = {"scene": name, "speed_multiple": multiple, "pz_v0": scene.pz_v0,
                   "status": res.status, "amplification": res.pull_off / lj.pull_off,
                   "wall_s": w, "pz_wall_s": w_pz, "ratio": w_pz / w, "steps": lj.steps,
                   "pz_steps": res.steps, "factorizations": lj.factorizations,
                   "pz_factorizations": res.factorizations, "crack_pz_wall_s": w_crack}
            rows.append(row)
            print(f"{name:28s} pz_v0 {multiple:g} x v: amplification {row['amplification']:.3f}"
                  f" ({res.status}), cost {row['ratio']:.2f} ({w_pz * 1e3:.0f} / {w * 1e3:.0f} ms,"
                  f" steps {res.steps} / {lj.steps}); crack-front {w_crack * 1e3:.0f} ms",
                  flush=True)
    return rows



def _run(model: str, fields: dict, rate: float, pz: bool):
    extra = PZ if pz else {}
    scene = Scene(model=model, mu=MU, a0=A0, rate=rate, **fields, **extra)
    return _wall(scene, bem.simulate if model == "bem" else simulate)


def measure() -> dict:
    _run("bem", CASES[0][1], 1.0, True)           # compile (or load) the kernels first
    rows = []
    for name, fields, rates in CASES:
        for rate in rates:
            (bem_pz, _), (plain, _) = (_run("bem", fields, rate, True),
                                       _run("bem", fields, rate, False))
            timed = [(_run("bem", fields, rate, True)[1], _run("bem", fields, rate, False)[1])
                     for _ in range(REPEATS)]
            w_pz, w = (float(np.min(x)) for x in zip(*timed))
            (cr_pz, _), (cr, _) = _run("crack", fields, rate, True), _run("crack", fields, rate, False)
            row = {"case": name, "rate": rate, "bem_pull_off": plain.pull_off,
                   "bem_pz_pull_off": bem_pz.pull_off, "bem_pz_status": bem_pz.status,
                   "bem_pz_reason": bem_pz.reason, "bem_pz_error_estimate": bem_pz.error_estimate,
                   "crack_pull_off": cr.pull_off, "crack_pz_pull_off": cr_pz.pull_off,
                   "bem_amplification": bem_pz.pull_off / plain.pull_off,
                   "crack_amplification": cr_pz.pull_off / cr.pull_off,
                   "crack_speed": bem_pz.crack_speed, "bem_wall_s": w, "bem_pz_wall_s": w_pz,
                   "bem_steps": plain.steps, "bem_pz_steps": bem_pz.steps,
                   "bem_newton_iterations": plain.newton_iterations,
                   "bem_pz_newton_iterations": bem_pz.newton_iterations}
            row["difference"] = row["bem_amplification"] / row["crack_amplification"] - 1.0
            rows.append(row)
            print(f"{name:16s} rate {rate:7g}: amplification BEM {row['bem_amplification']:.4f}"
                  f" crack-front {row['crack_amplification']:.4f} ({row['difference']:+.2%}); "
                  f"BEM wall {w_pz:.2f} s with, {w:.2f} s without ({bem_pz.status})", flush=True)
    bench = bench_cost()
    ratios = {m: [r["ratio"] for r in bench if r["speed_multiple"] == m]
              for m in BENCH_SPEED_MULTIPLES}
    summary = {f"{m:g}": {"median": float(np.median(v)), "max": float(np.max(v))}
               for m, v in ratios.items()}
    crack = [r["crack_pz_wall_s"] for r in bench]
    summary["crack_front_wall_s"] = {"median": float(np.median(crack)), "max": float(np.max(crack))}
    for m, v in summary.items():
        if m == "crack_front_wall_s":
            print(f"the crack-front model with the process zone: median {v['median'] * 1e3:.0f} ms,"
                  f" max {v['max'] * 1e3:.0f} ms a scene")
            continue
        print(f"cost on the bench scenes, pz_v0 = {m} x the crack speed: median {v['median']:.2f},"
              f" max {v['max']:.2f}")
    return {"what": "BEM vs crack-front model with a Gent-Schultz process zone; the BEM's cost",
            "command": "make pz-check", "mu": MU, "a0": A0, "process_zone": PZ,
            "beta": opening_rate_scale(MU, PZ["pz_xi"]), "rows": rows,
            "bench_xi": BENCH_XI, "bench_cost": bench, "bench_cost_ratio": summary,
            "provenance": provenance()}


def main(argv=None) -> int:
    return measurement_main("python -m sweep.bench.process_zone_check", __doc__, measure, OUT, argv)


if __name__ == "__main__":
    sys.exit(main())
