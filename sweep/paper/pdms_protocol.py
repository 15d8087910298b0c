r"""The paper's PDMS experiment as run: approach to the preload, 60 s dwell, retraction
(issue 36 item 4), beside the relaxed start every other PDMS curve uses.

The paper's tests "comprised three sequential steps: loading, dwelling, and unloading": the lens
loaded to P0 = 1.5 mN, a 60 s dwell, then retraction at the unloading speed; its simulations (and
:mod:`sweep.paper.pdms`) start instead from the fully relaxed contact at that preload. Here the
hereditary BEM runs both, scene by scene: the protocol (:class:`sweep.scene.Protocol`: first
contact, approach at :data:`PROTOCOL` ``approach_speed_um_s`` to the preload, the dwell at that
force, retraction) and the relaxed start at the preload's relaxed JKR radius, at the paper's
speeds, and reports their ratio.

The BEM cannot run the PDMS's own Tabor parameter with a protocol: a protocol's crack tip
crosses the contact from first contact out to the preload's radius, all of it on the fine mesh,
and at mu = 100 that mesh needs 161,887 nodes at the balanced preset (the engine's refusal,
measured). As :func:`sweep.paper.pdms.bem_case` does for the linear
BEM curve, the PDMS is run with h0 scaled to smaller Tabor parameters (:data:`MUS`; every other
input unchanged: the loads in pi dg R, a_ref and d_ref are the PDMS's), and the ratio
protocol/relaxed is reported at each: its spread over mu says how far it may be carried to the
PDMS's mu = 102.9 (the JKR limit, where the ratio is a property of the bulk's history).

The approach speed is not in the paper ("gradually loaded"): :data:`PROTOCOL` takes 1 um/s, the
slowest speed the paper measured at (0.98 um/s), and :data:`APPROACH_CHECK` measures what a ten
times faster approach changes.

``python -m sweep.paper.pdms_protocol --out results/pdms`` (``make pdms-protocol``, then ``make
pdms``) writes ``results/pdms/protocol.json``; ``make pdms`` reads it into REPORT.md
(:func:`sweep.paper.pdms.protocol_lines`).
"""
from __future__ import annotations

import dataclasses
import json
import math
import os
import time
from pathlib import Path

from ..campaign.store import provenance
from ..scene import Numerics
from .pdms import (PDMS_CASE, PDMS_PROTOCOL, PROTOCOL_NUMERICS, bem_case, pdms_scene,
                   protocol_key)

PROTOCOL = {k: v for k, v in PDMS_PROTOCOL.items() if k not in PROTOCOL_NUMERICS}
PRESET = PDMS_PROTOCOL["preset"]
REFINEMENTS = PDMS_PROTOCOL["refinements"]

#: the Tabor parameters the BEM runs the PDMS at (h0 scaled; sweep.paper.pdms.bem_case)
MUS = (3.0, 5.0, 8.0)
#: the paper's unloading speeds (um/s)
SPEEDS_UM_S = (1.0, 10.0, 100.0, 1.0e3, 1.0e4)
#: the numerics: the preset of PDMS_PROTOCOL with its refinements, the node cap raised so that
#: mu = 8's protocol mesh fits
MAX_NODES = 1400
#: (mu, unloading speed um/s, approach speed um/s): the approach ten times faster
APPROACH_CHECK = (5.0, 1.0e4, 10.0)


def _numerics() -> Numerics:
    return Numerics.preset(PRESET, max_nodes=MAX_NODES, refinements=REFINEMENTS)


def _row(res, si, wall) -> dict:
    """The SI summary of one BEM result of the SI scene ``si``."""
    ok = res.status == "ok"
    sc = si.scale
    return {"status": res.status, "reason": res.reason,
            "pull_off_mN": float(sc.load_physical(res.pull_off)) * 1e3 if ok else None,
            "pull_off_hat": float(res.pull_off) if ok else None,
            "error_estimate": float(res.error_estimate),
            "a0_hat": float(res.a0_result), "a0_mm": float(sc.a_ref * res.a0_result) * 1e3,
            "crack_speed_um_s": (float(sc.crack_speed_physical(res.crack_speed, si.tau0)) * 1e6
                                 if ok else None),
            "hysteresis_energy_hat": (float(res.hysteresis_energy)
                                      if math.isfinite(res.hysteresis_energy) else None),
            "steps": int(res.steps), "nodes": int(res.nodes_used), "wall_s": wall}


def protocol_point(speed_um: float, mu: float, case=None, protocol=None,
                   approach_speed_um: float | None = None) -> dict:
    """The PDMS at unloading speed ``speed_um`` [um/s] and Tabor parameter ``mu`` (h0 scaled),
    retracted from the relaxed start at the preload and after the protocol (approach at
    ``approach_speed_um``, default the protocol's, to the preload, dwell, retraction), both by
    the hereditary BEM (``model: bem``, :func:`_numerics`).

    Returns
    -------
    dict
        ``speed_um_s``, ``mu``, ``approach_speed_um_s``, ``relaxed`` and ``protocol``
        (:func:`_row`: pull-off in mN and pi dg R, its error estimate, the contact radius the
        retraction starts from, ...), ``ratio`` (protocol over relaxed pull-off) and
        ``combined_error`` (the sum of the two rows' error estimates: a ratio closer to 1 than
        this is no difference the numerics can tell).
    """
    from ..engine.models import simulate

    case = PDMS_CASE if case is None else case
    protocol = PROTOCOL if protocol is None else protocol
    approach = protocol["approach_speed_um_s"] if approach_speed_um is None else approach_speed_um
    relaxed_si = pdms_scene(float(speed_um) * 1e-6, bem_case(case, mu))
    protocol_si = dataclasses.replace(relaxed_si, approach_speed=float(approach) * 1e-6,
                                      dwell=float(protocol["dwell_s"]),
                                      dwell_hold=protocol["dwell_hold"])
    rows = {}
    for name, si in (("relaxed", relaxed_si), ("protocol", protocol_si)):
        t0 = time.perf_counter()
        res = simulate(si.to_scene(model="bem"), _numerics())
        rows[name] = _row(res, si, time.perf_counter() - t0)
        # the load the retraction starts from: the relaxed start's first record, the
        # protocol's last before the retraction (phase 2)
        P = res.trajectory["P"]
        rows[name]["start_load_hat"] = float(P[0] if name == "relaxed" else
                                             P[res.trajectory["phase"] < 2][-1])
    # the relaxed start at the contact the dwell ended with: the same geometry, the bulk's
    # history apart (the relaxed start at the preload's JKR radius differs from it by the LJ
    # law's finite-mu correction as well)
    same_si = dataclasses.replace(relaxed_si, preload=None,
                                  a0=rows["protocol"]["a0_hat"] * relaxed_si.scale.a_ref)
    t0 = time.perf_counter()
    res = simulate(same_si.to_scene(model="bem"), _numerics())
    rows["relaxed_same_radius"] = _row(res, same_si, time.perf_counter() - t0)
    ok = {k: rows[k]["status"] == "ok" for k in rows}

    def ratio(a, b):
        return rows[a]["pull_off_hat"] / rows[b]["pull_off_hat"] if ok[a] and ok[b] else None

    return {"speed_um_s": float(speed_um), "mu": float(mu), "approach_speed_um_s": float(approach),
            **rows, "ratio": ratio("protocol", "relaxed"),
            "ratio_same_radius": ratio("protocol", "relaxed_same_radius"),
            "combined_error": rows["relaxed"]["error_estimate"] + rows["protocol"]["error_estimate"],
            "combined_error_same_radius": (rows["relaxed_same_radius"]["error_estimate"]
                                           + rows["protocol"]["error_estimate"])}


def resumable(commit: str) -> bool:
    """Whether a file written by ``commit`` (:func:`sweep.campaign.store.provenance`) may be
    resumed: a clean commit of a git checkout, not "unknown" or "-dirty" (whose code the
    string does not pin)."""
    return commit != "unknown" and not commit.endswith("-dirty")


def protocol_curve(path, mus=MUS, speeds=SPEEDS_UM_S, log=print) -> dict:
    """Every (mu, speed) point of :func:`protocol_point` and the approach check, written to the
    JSON file ``path`` (resumed: a point already there for the same case and protocol, written
    by the same clean commit (:func:`resumable`), is not run again; each new one is written
    when done; a file another commit wrote is computed again).

    Returns
    -------
    dict
        ``case``, ``protocol``, ``preset``, ``points`` (one per mu and speed), ``approach_check``
        and, per speed, ``summary``: the ratio at each mu, its spread (max - min) and the one at
        the largest mu.
    """
    path = Path(path)
    key = protocol_key()
    commit = provenance()["git_commit"]
    data = {**key, "git_commit": commit, "points": [], "approach_check": None}
    if path.is_file():
        old = json.loads(path.read_text())
        # resumed only by the clean commit that wrote it: another engine may compute other
        # numbers for the same case, test and numerics
        if (all(old.get(k) == v for k, v in key.items()) and old.get("git_commit") == commit
                and resumable(commit)):
            data = old
            log(f"{path}: resuming the {len(old['points'])} points commit {commit[:12]} made")
        else:
            log(f"{path}: made by {str(old.get('git_commit', 'an earlier version'))[:18]} "
                f"or for another case: every point computed again")

    def save():
        data["summary"] = summary(data["points"])
        tmp = path.with_suffix(".json.tmp")
        tmp.write_text(json.dumps(data, indent=1, default=float) + "\n")
        os.replace(tmp, path)

    path.parent.mkdir(parents=True, exist_ok=True)
    done = {(p["mu"], p["speed_um_s"]) for p in data["points"]}
    for mu in mus:
        for v in speeds:
            if (float(mu), float(v)) in done:
                continue
            p = protocol_point(v, mu)
            log(f"mu {mu:g}, {v:g} um/s: relaxed {p['relaxed']['pull_off_mN']} mN, protocol "
                f"{p['protocol']['pull_off_mN']} mN, ratio {p['ratio']} "
                f"({p['protocol']['status']} {p['protocol']['reason'][:80]})")
            data["points"].append(p)
            data["points"].sort(key=lambda q: (q["mu"], q["speed_um_s"]))
            save()
    if data.get("approach_check") is None:
        mu, v, approach = APPROACH_CHECK
        data["approach_check"] = protocol_point(v, mu, approach_speed_um=approach)
    save()
    return data


def summary(points) -> dict:
    """Per unloading speed (um/s, as a string key): the protocol's pull-off over the relaxed
    start's at the preload's JKR radius (``ratio``) and at the protocol's own final radius
    (``ratio_same_radius``) at each mu, the first's spread over mu and both at the largest mu
    (None where a run failed)."""
    out = {}
    for v in sorted({p["speed_um_s"] for p in points}):
        at = {p["mu"]: p for p in points if p["speed_um_s"] == v}
        ratios = [p["ratio"] for p in at.values() if p["ratio"] is not None]
        top = at[max(at)]
        out[f"{v:g}"] = {
            "ratio_by_mu": {f"{m:g}": p["ratio"] for m, p in sorted(at.items())},
            "ratio_same_radius_by_mu": {f"{m:g}": p["ratio_same_radius"]
                                        for m, p in sorted(at.items())},
            "spread": (max(ratios) - min(ratios)) if len(ratios) > 1 else None,
            "ratio_largest_mu": top["ratio"],
            "ratio_same_radius_largest_mu": top["ratio_same_radius"]}
    return out


def main(argv=None) -> int:
    import argparse

    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--out", default="results/pdms", help="output directory")
    args = ap.parse_args(argv)
    data = protocol_curve(Path(args.out) / "protocol.json")
    print(json.dumps(data["summary"], indent=1))
    return 0


if __name__ == "__main__":  # pragma: no cover
    raise SystemExit(main())
