"""What the test as run costs: a protocol scene against its relaxed start (``make protocol-cost``).

For each scene of :data:`SCENES` (mu 5 on the BEM's graded mesh, balanced preset) the wall
time of the protocol (approach to the preload, dwell, retraction) against the relaxed start at
the contact the dwell ended with (``a0 = a0_result``: the same retraction from a relaxed
contact), in one process, the kernels compiled first, each scene run once untimed, then
:data:`REPEATS` alternating timed runs each, the median. Written to
``results/protocol/cost.json`` with a table on stdout.

``python -m sweep.bench.protocol_cost [--out PATH]``
"""
from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np

from ..campaign.store import provenance
from ..engine import bem
from ..scene import Numerics, Scene
from . import measurement_main

#: (name, scene fields) of the protocol scenes
SCENES = (
    ("MPL k 0.1, rate 1, dwell 10 at force", dict(n=0.5, k=0.1, rate=1.0, approach_rate=1.0,
                                                  preload=2.0, dwell=10.0)),
    ("MPL k 0.1, rate 100, dwell 10 at depth", dict(n=0.5, k=0.1, rate=100.0, approach_rate=1.0,
                                                    preload=2.0, dwell=10.0,
                                                    dwell_hold="depth")),
    ("MPL k 0.3, rate 10, no dwell", dict(n=0.8, k=0.3, rate=10.0, approach_rate=10.0,
                                          preload=2.0, dwell=0.0)),
    ("SLS k 0.2, rate 1, dwell 100 at force", dict(material="sls", n=0.5, k=0.2, rate=1.0,
                                                   approach_rate=1.0, preload=4.0, dwell=100.0)),
)
MU = 5.0
REPEATS = 3
OUT = Path("results") / "protocol" / "cost.json"


def _timed(scene: Scene):
    t0 = time.perf_counter()
    res = bem.simulate(scene, Numerics.preset("balanced"))
    return res, time.perf_counter() - t0


def measure() -> dict:
    rows = []
    for name, fields in SCENES:
        protocol_scene = Scene(mu=MU, **fields)
        res, _ = _timed(protocol_scene)
        relaxed_fields = {k: v for k, v in fields.items()
                          if k not in ("approach_rate", "preload", "dwell", "dwell_hold")}
        relaxed_scene = Scene(mu=MU, a0=res.a0_result, **relaxed_fields)
        relaxed, _ = _timed(relaxed_scene)
        walls = [(_timed(protocol_scene)[1], _timed(relaxed_scene)[1]) for _ in range(REPEATS)]
        w_protocol, w_relaxed = (float(np.median(x)) for x in zip(*walls))
        row = {"scene": name, "status": res.status, "pull_off": res.pull_off,
               "relaxed_pull_off": relaxed.pull_off, "a0_after_dwell": res.a0_result,
               "steps": res.steps, "relaxed_steps": relaxed.steps,
               "wall_s": w_protocol, "relaxed_wall_s": w_relaxed,
               "ratio": w_protocol / w_relaxed}
        rows.append(row)
        print(f"{name:40s} {res.status}: {w_protocol:.3f} s against {w_relaxed:.3f} s relaxed "
              f"({row['ratio']:.2f}x); pull-off {res.pull_off:.4f} against {relaxed.pull_off:.4f}",
              flush=True)
    ratios = [r["ratio"] for r in rows]
    print(f"ratio: median {np.median(ratios):.2f}, range {min(ratios):.2f}-{max(ratios):.2f}")
    return {"what": "a protocol scene's wall time against its relaxed start's",
            "command": "make protocol-cost", "mu": MU, "rows": rows,
            "median_ratio": float(np.median(ratios)), "provenance": provenance()}


def main(argv=None) -> int:
    return measurement_main("python -m sweep.bench.protocol_cost", __doc__, measure, OUT, argv)


if __name__ == "__main__":
    sys.exit(main())
