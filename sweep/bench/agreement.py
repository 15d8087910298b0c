"""Where the models agree: BEM vs crack-front model vs the PB estimate on the same scenes.

``python -m sweep.bench.agreement --out results/agreement/agreement.json`` (``make agreement``):

* mu = 3.24 (the paper's), n = 0.8, k = 0.1, a0 in {1, 2, 3, 4, 6, 8}, rates {1, 10^2.5, 1e4}:
  finite-size effects of the crack-front model at small a0 and its relaxed-bulk assumption
  at high rates;
* a0 = 3, rate 10^2.5 at increasing mu (3.24, 6, 10), the BEM meshed so that the process zone
  l0 = 1.693/mu^2 spans ``zone_nodes`` spacings (the crack-front model is the mu -> inf limit
  of the JKR edge).

The BEM uses the "balanced" preset (nodes raised where mu needs them); every row records the
pull-off, the crack speed at pull-off and the wall time of each model, and the relative
differences crack/BEM - 1 and pb/BEM - 1.
"""
from __future__ import annotations

import argparse
import json
import math
import os
import sys
import time
from pathlib import Path

from ..campaign.store import provenance
from ..engine.crack_front import simulate_crack
from ..engine.models import bem_node_budget, bem_nodes_needed, simulate_pb
from ..engine.problem import BEM_MU_RANGE
from ..scene import Numerics, Scene
from ..engine.bem import simulate

A0S = (1.0, 2.0, 3.0, 4.0, 6.0, 8.0)
RATES = (1.0, 10**2.5, 1e4)
MUS = (3.24, 6.0, 10.0)


def _numerics(scene: Scene) -> Numerics:
    """Balanced numerics; the graded mesh resolves l0 at every mu by itself, given room."""
    return Numerics.preset("balanced", max_nodes=5000)


def _row(scene: Scene) -> dict:
    num = _numerics(scene)
    bem = simulate(scene, num)
    crack = simulate_crack(scene)
    pb = simulate_pb(scene)
    row = {"n": scene.n, "k": scene.k, "mu": scene.mu, "a0": scene.a0, "rate": scene.rate,
           "bem_nodes": bem.nodes_used, "bem_status": bem.status, "bem_reason": bem.reason}
    for name, r in (("bem", bem), ("crack", crack), ("pb", pb)):
        row[f"{name}_pull_off"] = r.pull_off
        row[f"{name}_crack_speed"] = r.crack_speed
        row[f"{name}_wall_s"] = r.wall_s
    for name in ("crack", "pb"):
        row[f"{name}_vs_bem"] = (row[f"{name}_pull_off"] / bem.pull_off - 1.0) if bem.ok \
            else math.nan
    return row


def run(a0s=A0S, rates=RATES, mus=MUS) -> dict:
    t0 = time.perf_counter()
    rows = []
    for a0 in a0s:
        for rate in rates:
            rows.append(_row(Scene(n=0.8, k=0.1, mu=3.24, a0=a0, rate=rate)))
            print(_fmt(rows[-1]), flush=True)
    mu_rows = []
    for mu in mus:
        mu_rows.append(_row(Scene(n=0.8, k=0.1, mu=mu, a0=3.0, rate=10**2.5)))
        print(_fmt(mu_rows[-1]), flush=True)

    return {"a0_scan": rows, "mu_scan": mu_rows, "wall_s": time.perf_counter() - t0,
            "git_commit": provenance()["git_commit"]}


def _fmt(r: dict) -> str:
    return (f"mu={r['mu']:<5g} a0={r['a0']:<4g} rate={r['rate']:<8.4g} N={r['bem_nodes']:<5d} "
            f"BEM {r['bem_pull_off']:.4f} crack {r['crack_pull_off']:.4f} "
            f"({100 * r['crack_vs_bem']:+.1f} %) pb {r['pb_pull_off']:.4f} "
            f"({100 * r['pb_vs_bem']:+.1f} %)  v_a BEM {r['bem_crack_speed']:.4g} "
            f"crack {r['crack_crack_speed']:.4g}  wall BEM {r['bem_wall_s']:.2f} s "
            f"crack {r['crack_wall_s']:.3f} s")


def merged(res: dict, extra=()) -> dict:
    """``res`` with the mu-scan rows of other runs (e.g. the costly high-mu points, stored in
    ``agreement_mu*.json``) appended, sorted by mu; a0-scan rows are merged the same way."""
    out = {"a0_scan": list(res.get("a0_scan", [])), "mu_scan": list(res.get("mu_scan", [])),
           "sources": [], "wall_s": res.get("wall_s", math.nan)}
    out["commits"] = [res.get("git_commit", "before 4e9c183 (the mesh of then)")]
    for path in extra:
        other = json.loads(Path(path).read_text())
        out["commits"].append(other.get("git_commit", "before 4e9c183 (the mesh of then)"))
        out["a0_scan"] += other.get("a0_scan", [])
        out["mu_scan"] += other.get("mu_scan", [])
        out["sources"].append(Path(path).name)
    out["mu_scan"].sort(key=lambda r: (r["mu"], r["a0"], r["rate"]))
    return out


def _reach(res: dict) -> str:
    """Why the mu scan stops where it does: the highest mu measured, its BEM cost, and the
    nodes the BEM's range end (sweep.engine.problem.BEM_MU_RANGE) would need with today's mesh."""
    top = max(res["mu_scan"], key=lambda r: r["mu"], default=None)
    if top is None:
        return ""
    mu_end = BEM_MU_RANGE[1]
    end = Scene(n=top["n"], k=top["k"], mu=mu_end, a0=top["a0"], rate=top["rate"])
    num = _numerics(end)
    return (f"The highest mu measured, {top['mu']:g}, cost the BEM {top['bem_wall_s']:.0f} s "
            f"({top['bem_nodes']} nodes); the end of the BEM's range, mu = {mu_end:g}, needs "
            f"{bem_nodes_needed(end, num)} nodes on today's balanced mesh (budget "
            f"{bem_node_budget(num)}), beyond this machine's time for the check.")


def summary(res: dict) -> str:
    """The agreement in a few lines: crack-front and PB estimate against the BEM, per rate
    over the a0 scan (finite-size effects at a0 < 3) and along mu."""
    def pct(rows, key):
        v = [100 * r[key] for r in rows if math.isfinite(r[key])]
        if not v:
            return "--"
        lo, hi = min(v), max(v)
        return f"{lo:+.1f} %" if abs(hi - lo) < 0.05 else f"{lo:+.1f} .. {hi:+.1f} %"

    L = ["| scenes | crack/BEM - 1 | pb/BEM - 1 |", "| --- | --- | --- |"]
    a0s = res["a0_scan"]
    for rate in sorted({r["rate"] for r in a0s}):
        at = [r for r in a0s if r["rate"] == rate]
        for label, sel in (("a0 >= 3", [r for r in at if r["a0"] >= 3]),
                           ("a0 < 3", [r for r in at if r["a0"] < 3])):
            if sel:
                a0_list = ", ".join(f"{r['a0']:g}" for r in sel)
                L.append(f"| mu = {sel[0]['mu']:g}, rate {rate:.4g}, {label} (a0 = {a0_list}) "
                         f"| {pct(sel, 'crack_vs_bem')} | {pct(sel, 'pb_vs_bem')} |")
    for r in res["mu_scan"]:
        L.append(f"| mu = {r['mu']:g}, a0 = {r['a0']:g}, rate {r['rate']:.4g} "
                 f"({r['bem_nodes']} BEM nodes) | {pct([r], 'crack_vs_bem')} | "
                 f"{pct([r], 'pb_vs_bem')} |")
    return "\n".join(L) + "\n"


def table(res: dict) -> str:
    """Markdown tables of a :func:`run` result."""
    head = ("| mu | a0 | rate | BEM nodes | P BEM | P crack | crack/BEM - 1 | P pb | pb/BEM - 1 "
            "| v_a BEM | v_a crack | wall BEM [s] | wall crack [s] |\n"
            "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |\n")
    lines = []
    for part in ("a0_scan", "mu_scan"):
        lines.append(f"\n### {part}\n\n" + head)
        for r in res[part]:
            lines.append(f"| {r['mu']:g} | {r['a0']:g} | {r['rate']:.4g} | {r['bem_nodes']} "
                         f"| {r['bem_pull_off']:.4f} | {r['crack_pull_off']:.4f} "
                         f"| {100 * r['crack_vs_bem']:+.1f} % | {r['pb_pull_off']:.4f} "
                         f"| {100 * r['pb_vs_bem']:+.1f} % | {r['bem_crack_speed']:.4g} "
                         f"| {r['crack_crack_speed']:.4g} | {r['bem_wall_s']:.2f} "
                         f"| {r['crack_wall_s']:.3f} |\n")
    return "".join(lines)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--out", default="results/agreement/agreement.json")
    ap.add_argument("--table-only", action="store_true",
                    help="Only rewrite the markdown tables from an existing JSON.")
    ap.add_argument("--mus", default=None,
                    help="Comma list of mu for the mu scan (default 3.24,6,10; mu = 15 needs "
                         "1229 nodes and about half an hour).")
    ap.add_argument("--no-a0-scan", action="store_true", help="Skip the a0 scan at mu = 3.24.")
    args = ap.parse_args(argv)
    out = Path(args.out)
    os.makedirs(out.parent, exist_ok=True)
    if args.table_only:
        if not out.is_file():
            print(f"error: --out: no such file {str(out)!r} (run without --table-only first)",
                  file=sys.stderr)
            return 2
        res = json.loads(out.read_text())
    else:
        mus = MUS if args.mus is None else tuple(float(x) for x in args.mus.split(","))
        res = run(a0s=() if args.no_a0_scan else A0S, mus=mus)
        tmp = out.with_suffix(".json.tmp")
        tmp.write_text(json.dumps(res, indent=1) + "\n")
        os.replace(tmp, out)
    # the default file gathers the costly high-mu points measured apart (agreement_mu*.json)
    extra = sorted(p for p in out.parent.glob("agreement_mu*.json") if p != out) \
        if out.name == "agreement.json" else []
    full = merged(res, extra)
    md = out.with_suffix(".md")
    src = (f" Rows of {', '.join(full['sources'])} (measured apart: `make agreement-high-mu`) "
           "are merged into the mu scan." if full["sources"] else "")
    md.write_text("# Model agreement: BEM vs crack-front model vs PB estimate "
                  "(n = 0.8, k = 0.1; `make agreement`)\n\n"
                  "Same scene, three models: the BEM (balanced preset), the crack-front model "
                  "(JKR edge with the Persson-Brener Gamma(v) of the MPL spectrum, the mu -> "
                  "infinity limit) and the paper's closed-form PB estimate (v-r fit made at "
                  "mu = 3.24)." + src + " " + _reach(full) + " Measured at commit(s) "
                  + ", ".join(dict.fromkeys(full["commits"])) + ".\n\n"
                  "## Summary\n\n" + summary(full) + table(full))
    print(out)
    print(md)
    return 0


if __name__ == "__main__":  # pragma: no cover
    raise SystemExit(main())
