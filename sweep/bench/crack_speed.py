r"""How accurate is the crack speed at pull-off, and what does its fit's window do to it?

The crack speed ``Result.crack_speed`` is -da/dt at the pull-off instant, read off the
recorded radius a(t) by a quadratic least-squares fit over the records within a window of
the pull-off radius (:func:`sweep.engine.postprocess.crack_speed_on_mesh`: three fine
spacings). a(t) crosses the nodes with a kink at each (the contact radius is interpolated
linearly between nodes), so the window must span a few spacings; and the crack accelerates
through the pull-off, so a wide window reads a curved a(t) with a quadratic.

This study runs each scene with the presets and with a fine reference (:data:`REFERENCE`),
collects every fit's records (:func:`sweep.engine.postprocess.capture_fits`) and reads the
crack speed again under each window rule of :data:`WINDOW_RULES`. The reference is read
with its narrowest window (three of its spacings, a 16th of the tip zone, over steps a
quarter of balanced's): the derivative at the pull-off instant, which every window tends to
as the mesh and the steps are refined. Reported per preset, rule and scene set: the largest,
90th-percentile and median relative error, and how many scenes miss the preset's crack-speed
target (``sweep.bench.tradeoff.CRACK_SPEED_TARGETS``); beside them the reference's own spread
over the rules (how much the answer depends on the window where a(t) is curved).

Scenes: the v0.1 threshold grid thinned to n 0.4 / 0.8 / 1.6, rates 1 / 1e3 / 1e6, a0 1.5 /
3 / 4.5 / 8 at mu = 3.24 (36), the three tradeoff scenes, and the error-coverage sample's
scenes whose reference finished in under :data:`COVERAGE_REFERENCE_S` seconds
(``results/error_coverage/coverage.json``: mu 0.01-4, MPL and SLS).

``python -m sweep.bench.crack_speed`` (``make crack-speed``, about 6 minutes on 2 cores)
writes ``results/crack_speed/crack_speed.json``.
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
from ..engine.postprocess import capture_fits, crack_speed_on_mesh
from ..engine.problem import derive
from ..scene import Numerics, Scene
from .tradeoff import CRACK_SPEED_TARGETS, TRADEOFF_SCENES

PRESET_NAMES = ("fast", "balanced", "accurate")
#: numerics variants run beside the presets (name: preset and overrides)
VARIANTS = {"balanced_da_max_1": ("balanced", dict(da_max=1.0, da_max_pulloff=None)),
            "balanced_previous": ("balanced", dict(da_max=0.6, da_max_pulloff=None)),
            "balanced_step_0.2": ("balanced", dict(step=0.2)),
            "fast_step_0.5": ("fast", dict(step=0.5)),
            "fast_step_0.5_pulloff_0.6": ("fast", dict(step=0.5, da_max_pulloff=0.6))}
#: the reference: the accurate preset at 48 spacings per tip zone, a quarter of balanced's
#: steps, Newton to 1e-9 h0; no error estimate
REFERENCE = ("accurate", dict(band_resolution=48.0, step=0.05, da_max=0.15, tol=1e-9,
                              max_nodes=5000))
#: the reference's own check, on the coverage sample's scenes (where the crack speed depends
#: most on the mesh): the same at 72 spacings per tip zone and grading 1.03
REFERENCE_FINER_MESH = ("accurate", dict(band_resolution=72.0, grading=1.03, step=0.05,
                                         da_max=0.15, tol=1e-9, max_nodes=8000))
#: the rule the reference is read with (see the module's text)
REFERENCE_RULE = "3 spacings"
#: the fit's window (a_ref) from the fine spacing s and the tip zone z (a_ref); the first is
#: the engine's (postprocess.crack_speed_on_mesh)
WINDOW_RULES = {
    "3 spacings": lambda s, z: 3.0 * s,
    "5 spacings": lambda s, z: 5.0 * s,
    "max(3 spacings, 0.25 z)": lambda s, z: max(3.0 * s, 0.25 * z),
    "max(3 spacings, 0.3 z)": lambda s, z: max(3.0 * s, 0.3 * z),
    "max(3 spacings, 0.4 z)": lambda s, z: max(3.0 * s, 0.4 * z),
}
#: coverage-sample scenes whose reference (error_coverage.REFERENCE) took longer are left out
COVERAGE_REFERENCE_S = 40.0
COVERAGE_FILE = Path("results/error_coverage/coverage.json")


def threshold_scenes() -> dict:
    """The 36 scenes of the thinned v0.1 threshold grid (k 0.1, mu 3.24)."""
    return {f"threshold n{n} rate{rate:g} a0{a0:g}": dict(n=n, k=0.1, mu=3.24, a0=a0, rate=rate)
            for n in (0.4, 0.8, 1.6) for rate in (1.0, 1e3, 1e6) for a0 in (1.5, 3.0, 4.5, 8.0)}


def coverage_scenes(path: Path = COVERAGE_FILE, max_reference_s: float = COVERAGE_REFERENCE_S) -> dict:
    """The error-coverage sample's scenes whose reference finished ok within
    ``max_reference_s`` seconds."""
    if not Path(path).exists():
        raise SystemExit(f"crack_speed: {path} is missing (make error-coverage writes it)")
    rows = json.loads(Path(path).read_text())["rows"]
    out = {}
    for i, row in enumerate(rows):
        ref = row.get("reference") or {}
        if ref.get("status") == "ok" and ref.get("wall_s", math.inf) < max_reference_s:
            s = row["scene"]
            out[f"coverage {i} mu{s['mu']:g}"] = s
    return out


def numerics_of(label: str) -> Numerics:
    """The numerics run under ``label`` (a preset, a :data:`VARIANTS` name or "reference"),
    without the error estimate's second solve (it does not change the crack speed)."""
    preset, over = {"reference": REFERENCE, "reference_finer_mesh": REFERENCE_FINER_MESH,
                    **VARIANTS}.get(label, (label, {}))
    return Numerics.preset(preset, pull_off_rtol=0.0, time_budget_s=600.0, **over)


def run_scene(name: str, scene: dict, label: str) -> dict:
    """One scene under one numerics: its result and the inputs of its crack-speed fit
    (``fit``: None where no fit was made, e.g. a pull-off at the initial state)."""
    from ..engine.models import simulate
    num = numerics_of(label)
    sc = Scene(**scene)
    with capture_fits() as fits:
        res = simulate(sc, num)
    fit = fits[-1] if (fits and res.ok) else None
    return dict(name=name, label=label, scene=scene, status=res.status, reason=res.reason,
                crack_speed=res.crack_speed, steps=res.steps, wall_s=res.wall_s,
                tip_zone=derive(sc, num).tip_zone, fit=fit)


def speed_under(row: dict, rule: str) -> float:
    """The crack speed of ``row`` read with the window of ``rule`` (the row's own where it
    made no fit)."""
    fit = row["fit"]
    if not fit:
        return row["crack_speed"]
    width = WINDOW_RULES[rule](fit["spacing"], row["tip_zone"])
    return float(crack_speed_on_mesh(np.asarray(fit["t"]), np.asarray(fit["a"]), fit["t_star"],
                                     width, fit["lo"], fit["hi"], window_nodes=1.0))


def spread_over_rules(row: dict) -> float:
    """The relative spread of ``row``'s crack speed over :data:`WINDOW_RULES`."""
    v = [speed_under(row, rule) for rule in WINDOW_RULES]
    return (max(v) - min(v)) / abs(float(np.median(v)))


def _stats(errors) -> dict:
    e = np.asarray(errors, dtype=float)
    if e.size == 0:
        return dict(scenes=0)
    return dict(scenes=int(e.size), max=float(e.max()), p90=float(np.quantile(e, 0.9)),
                median=float(np.median(e)))


def summarize(rows: list[dict]) -> dict:
    """Per scene set, numerics label and window rule: the crack-speed errors against the
    reference read with :data:`REFERENCE_RULE`, the reference's own spread over the rules,
    and its change on a finer mesh (where that ran)."""
    refs = {r["name"]: r for r in rows if r["label"] == "reference" and r["status"] == "ok"}
    finer = {r["name"]: r for r in rows if r["label"] == "reference_finer_mesh" and r["status"] == "ok"}
    sets = {"threshold_mu3.24": lambda n: not n.startswith("coverage"),
            "coverage_sample": lambda n: n.startswith("coverage")}
    out = {}
    for set_name, member in sets.items():
        spread = [spread_over_rules(ref) for name, ref in refs.items()
                  if member(name) and ref["fit"]]
        change = [abs(speed_under(finer[n], REFERENCE_RULE) - speed_under(refs[n], REFERENCE_RULE))
                  / abs(speed_under(refs[n], REFERENCE_RULE)) for n in finer if n in refs and member(n)]
        block = {"reference_spread_over_rules": _stats(spread),
                 "reference_change_on_finer_mesh": _stats(change)}
        labels = [lab for lab in (*PRESET_NAMES, *VARIANTS)
                  if any(r["label"] == lab for r in rows)]
        for lab in labels:
            target = CRACK_SPEED_TARGETS.get(VARIANTS.get(lab, (lab,))[0], math.nan)
            per_rule = {}
            for rule in WINDOW_RULES:
                errors, signed, worst = [], [], None
                for r in rows:
                    ref = refs.get(r["name"])
                    if r["label"] != lab or not member(r["name"]) or r["status"] != "ok" or not ref:
                        continue
                    v, v_ref = speed_under(r, rule), speed_under(ref, REFERENCE_RULE)
                    err = abs(v - v_ref) / abs(v_ref)
                    errors.append(err)
                    signed.append(v > v_ref)
                    if worst is None or err > worst[0]:
                        worst = (err, r["name"])
                per_rule[rule] = {**_stats(errors), "above_target": int(np.sum(np.asarray(errors) > target)),
                                  "read_faster": int(sum(signed)),
                                  "worst_scene": worst[1] if worst else None}
            failed = sum(1 for r in rows if r["label"] == lab and member(r["name"]) and r["status"] != "ok")
            block[lab] = {"crack_speed_target": target, "not_ok": failed, "rules": per_rule}
        out[set_name] = block
    return out


def per_scene(rows: list[dict]) -> list[dict]:
    """A row per scene: the reference's crack speed and spread, and each numerics' signed
    relative error (positive: read faster than the reference) with the engine's window
    (:data:`REFERENCE_RULE`)."""
    refs = {r["name"]: r for r in rows if r["label"] == "reference"}
    out = []
    for name, ref in refs.items():
        entry = dict(scene_name=name, scene=ref["scene"], reference_status=ref["status"])
        if ref["status"] == "ok":
            v_ref = speed_under(ref, REFERENCE_RULE)
            entry.update(reference_crack_speed=v_ref, pull_off_at_initial_state=ref["fit"] is None,
                         reference_spread=spread_over_rules(ref))
            for r in rows:
                if r["name"] == name and r["label"] != "reference":
                    entry[f"error_{r['label']}"] = ((speed_under(r, REFERENCE_RULE) - v_ref) / abs(v_ref)
                                                    if r["status"] == "ok" else None)
        out.append(entry)
    return out


def _print_summary(summary: dict) -> None:
    for set_name, block in summary.items():
        sp, ch = block["reference_spread_over_rules"], block["reference_change_on_finer_mesh"]
        print(f"{set_name}: reference spread over the rules max {sp.get('max', math.nan):.2e} "
              f"median {sp.get('median', math.nan):.2e}; change on a finer mesh max "
              f"{ch.get('max', math.nan):.2e} median {ch.get('median', math.nan):.2e}")
        for lab, b in block.items():
            if lab.startswith("reference_"):
                continue
            for rule, s in b["rules"].items():
                if s["scenes"]:
                    print(f"  {lab:18s} {rule:24s} n {s['scenes']:3d} max {s['max']:.2e} p90 "
                          f"{s['p90']:.2e} median {s['median']:.2e} above {b['crack_speed_target']:g}: "
                          f"{s['above_target']}")


def _main(argv=None) -> int:
    p = argparse.ArgumentParser(prog="python -m sweep.bench.crack_speed",
                                description=__doc__.split("\n\n")[0])
    p.add_argument("--jobs", "-j", type=int, default=2)
    p.add_argument("--out", default="results/crack_speed")
    p.add_argument("--quick", action="store_true",
                   help="the four a0 = 1.5 threshold scenes at n 0.4 and 1.6, rates 1 and 1e6 "
                        "(a smoke run, not the committed study)")
    args = p.parse_args(argv)
    from joblib import Parallel, delayed
    scenes = {**threshold_scenes(), **{f"tradeoff {k}": v for k, v in TRADEOFF_SCENES.items()}}
    if args.quick:
        scenes = {k: v for k, v in threshold_scenes().items()
                  if v["a0"] == 1.5 and v["n"] in (0.4, 1.6) and v["rate"] in (1.0, 1e6)}
    else:
        scenes.update(coverage_scenes())
    labels = (*PRESET_NAMES, *VARIANTS, "reference")
    jobs = [(name, s, lab) for name, s in scenes.items() for lab in labels]
    jobs += [(name, s, "reference_finer_mesh") for name, s in scenes.items()
             if name.startswith("coverage") or args.quick]
    print(f"crack_speed: {len(scenes)} scenes x {len(labels)} numerics (and the reference on a "
          f"finer mesh where it applies): {len(jobs)} runs on {args.jobs} workers", file=sys.stderr)
    t0 = time.perf_counter()
    rows = []
    for i, row in enumerate(Parallel(n_jobs=args.jobs, return_as="generator_unordered")(
            delayed(run_scene)(*j) for j in jobs), 1):
        rows.append(row)
        if i % 20 == 0 or i == len(jobs):
            print(f"  {i}/{len(jobs)} runs, {time.perf_counter() - t0:.0f} s", file=sys.stderr)
    summary = summarize(rows)
    _print_summary(summary)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    doc = {"summary": summary, "scenes": per_scene(rows),
           "reference": {"preset": REFERENCE[0], **REFERENCE[1], "read_with": REFERENCE_RULE},
           "reference_finer_mesh": {"preset": REFERENCE_FINER_MESH[0], **REFERENCE_FINER_MESH[1]},
           "window_rules": list(WINDOW_RULES), "variants": {k: {"preset": v[0], **v[1]} for k, v in VARIANTS.items()},
           "wall_s": time.perf_counter() - t0,
           "command": "python -m sweep.bench.crack_speed" + (" --quick" if args.quick else ""),
           **provenance()}
    (out / "crack_speed.json").write_text(json.dumps(to_jsonable(doc), indent=1))
    print(f"wrote {out / 'crack_speed.json'}", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(_main())
