r"""Stability at the extremes of the scene space: every corner of (n, k, rate, a0, mu).

Each scene runs with the model a user gets (:func:`sweep.engine.models.simulate`, model
"bem": the fixed-band or tip-following BEM, the quasi-static branch for k = 1) and is
judged against physical bounds that do not come from the BEM:

* lower: the relaxed elastic pull-off from the same a0, on the quasi-static branch
  (:func:`sweep.engine.quasistatic.elastic_pull_off`); at the slowest rate the pull-off must equal
  it (to ``SLOW_RTOL``): the substrate relaxes faster than it is unloaded;
* upper: 2/k, the pull-off of a crack whose work of adhesion is amplified by the full
  glassy ratio 1/k (JKR 1.5/k, DMT 2/k) -- or, for a large contact unloaded faster than it
  relaxes, the cohesive limit: the relaxed contact is frozen into a flat punch whose
  traction cannot exceed the LJ maximum tension sigma_0 = 16 mu/(9 sqrt(3) pi^(1/3)) over
  the radius a0 plus two tip zones, pi sigma_0 (a0 + 2 l)^2 (units pi dg R); the bound is
  the larger of the two.

A scene passes when it is ``ok`` with a finite pull-off inside the bounds, or ``failed``
with a reason; never NaN, an ok result outside the bounds, or a run over its time budget
without saying so. ``python -m sweep.bench.extremes [--quick]`` prints the table.
"""
from __future__ import annotations

import argparse
import itertools
import math
import time
from functools import lru_cache

from ..engine.models import simulate
from ..engine.problem import tip_zone
from ..engine.quasistatic import elastic_pull_off
from ..scene import Numerics, Scene

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
    """The relaxed elastic (quasi-static) pull-off from the contact radius a0."""
    return elastic_pull_off(mu, a_start=a0).pull_off


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
    if scene["rate"] == min(RATES) and abs(p / lo - 1.0) > SLOW_RTOL:
        return f"WRONG: slowest rate {p:.5g} != relaxed elastic {lo:.5g}"
    if p < lo * (1.0 - BOUND_RTOL) or p > hi * (1.0 + BOUND_RTOL):
        return f"WRONG: {p:.5g} outside [{lo:.5g}, {hi:.5g}]"
    return "ok"


def run(scenes, numerics=None, on_row=None) -> list[dict]:
    """Run and judge ``scenes`` (dicts of Scene fields); rows for :func:`print_table`
    (``on_row(row)`` is called as each is done)."""
    numerics = numerics or Numerics.preset("balanced", time_budget_s=TIME_BUDGET_S)
    rows = []
    for d in scenes:
        t0 = time.perf_counter()
        res = simulate(Scene(**d), numerics)
        rows.append(dict(d, status=res.status, pull_off=res.pull_off, model=res.model_used,
                         nodes=res.nodes_used, lower=relaxed_pull_off(d["mu"], d["a0"]),
                         upper=upper_bound(d["mu"], d["k"], d["a0"]),
                         verdict=judge(d, res), seconds=time.perf_counter() - t0))
        if on_row is not None:
            on_row(rows[-1])
    return rows


HEADER = (f"{'mu':>5} {'a0':>4} {'n':>4} {'k':>6} {'rate':>6} {'model':>7} {'status':>6} "
          f"{'pull_off':>9} {'lower':>7} {'upper':>9} {'nodes':>5} {'s':>6}  verdict")


def print_table(rows, out=print, header=True) -> None:
    if header:
        out(HEADER)
    for r in rows:
        out(f"{r['mu']:5g} {r['a0']:4g} {r['n']:4g} {r['k']:6g} {r['rate']:6g} {r['model']:>7} "
            f"{r['status']:>6} {r['pull_off']:9.5g} {r['lower']:7.4f} {r['upper']:9.4g} "
            f"{r['nodes']:5d} {r['seconds']:6.1f}  {r['verdict'][:110]}")


def _main(argv=None) -> int:
    p = argparse.ArgumentParser(prog="python -m sweep.bench.extremes",
                                description="stability at the extremes of the scene space")
    p.add_argument("--quick", action="store_true", help="the covering subset only")
    args = p.parse_args(argv)
    out = lambda s: print(s, flush=True)        # noqa: E731
    out(HEADER)
    rows = run(QUICK if args.quick else all_scenes(),
               on_row=lambda row: print_table([row], out=out, header=False))
    wrong = sum(r["verdict"].startswith("WRONG") for r in rows)
    failed = sum(r["status"] != "ok" for r in rows)
    print(f"{len(rows)} scenes: {len(rows) - failed} ok, {failed} failed with a reason, "
          f"{wrong} wrong; {sum(r['seconds'] for r in rows):.0f} s")
    return 1 if wrong else 0


if __name__ == "__main__":
    raise SystemExit(_main())
