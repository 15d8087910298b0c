r"""A seeded random sample across the declared ranges, run as a user runs it: ``sweep run``.

``python -m sweep.bench.random_sample configs --count 60`` writes the sweep configurations
``configs/random/auto.yaml`` and ``configs/random/bem.yaml`` (the same scenes, drawn
log-uniformly across the Scene's declared ranges, model ``auto`` and the default ``bem``;
balanced preset, 20 s time budget a scene), ``configs/random/protocol.yaml``: 80 scenes
with a test protocol (approach, dwell, retract; :func:`protocol_sample`), and
``configs/random/protocol_pz.yaml``: 40 with a protocol and a process zone. After ``sweep
run`` of each (``make random-sample``), ``python -m sweep.bench.random_sample summary``
counts, per sample, the scenes answered (``ok``), physically refused
(:func:`sweep.errors.is_physical_refusal`), failed otherwise, and hit by an internal error,
and the sweep's wall (:func:`scene_span`) and its scenes' summed walls, into
``results/random/summary.json``, and draws ``results/random/model_map.png``: which model answered each scene, over mu and the
rate, beside the crack-front model's measured difference from the BEM
(``sweep/engine/model_errors.json``).
"""
from __future__ import annotations

import argparse
import json
import math
from pathlib import Path

import numpy as np
import yaml

from ..campaign.store import load
from ..errors import is_physical_refusal
from .error_coverage import sample

ROOT = Path(__file__).resolve().parents[2]
CONFIGS = ROOT / "configs" / "random"
RESULTS = ROOT / "results" / "random"
MODELS = ("auto", "bem")
BUDGET_S = 20.0
#: the protocol sample (``configs/random/protocol.yaml``): its size, seed, and ranges,
#: log-uniform but n (uniform). mu stays at or below 6, where the protocol's graded mesh, whose
#: fine band reaches in to first contact, holds it at the balanced preset (beyond, from mu of
#: about 7, the tip-following mesh runs it: the sample below)
PROTOCOL_COUNT, PROTOCOL_SEED = 80, 41
PROTOCOL_RANGES = {"k": (0.005, 0.9), "mu": (0.3, 6.0), "rate": (1e-2, 1e6),
                   "approach_rate": (1e-2, 1e6), "preload": (0.05, 20.0)}
#: the protocol sample at large Tabor parameters (``configs/random/protocol_tabor.yaml``):
#: the same ranges but mu, drawn where the graded band exceeds max_nodes and the protocol
#: runs on the tip-following mesh (:class:`sweep.engine.tip_following.MarchWindow`)
PROTOCOL_TABOR_COUNT, PROTOCOL_TABOR_SEED = 40, 43
PROTOCOL_TABOR_MU = (6.0, 30.0)
#: a fifth of the scenes without a dwell, the others a dwell of 0.01-1e4 tau0 (log-uniform),
#: held at depth in three of ten; a fifth SLS
PROTOCOL_DWELL = (0.01, 1e4)
#: the protocol sample with a process zone (``configs/random/protocol_pz.yaml``): its size and
#: seed, and the Gent-Schultz law's reference speed (log-uniform) and exponent (uniform)
PROTOCOL_PZ_COUNT, PROTOCOL_PZ_SEED = 40, 77
PROTOCOL_PZ_V0, PROTOCOL_PZ_XI = (0.3, 30.0), (0.3, 0.8)
#: the samples ``summary`` counts: the two of :data:`MODELS`, and the protocols'
SAMPLES = MODELS + ("protocol", "protocol_pz", "protocol_tabor")


def sample_config(count: int, seed: int, model: str) -> dict:
    """The sweep configuration of ``count`` random scenes (a grid of one-point blocks)."""
    return {"name": f"random-{model}",
            "description": f"{count} scenes drawn log-uniformly across the declared ranges "
                           f"(seed {seed}), model {model}",
            "grid": [dict(d, model=model) for d in sample(count, seed, bem_range=False)],
            "numerics": {"preset": "balanced", "time_budget_s": BUDGET_S},
            "output": f"results/random/{model}.h5"}


def protocol_sample(count: int = PROTOCOL_COUNT, seed: int = PROTOCOL_SEED,
                    process_zone: bool = False, mu: tuple | None = None) -> list[dict]:
    """``count`` scenes with a test protocol (approach, dwell, retract), drawn from
    :data:`PROTOCOL_RANGES` (mu from ``mu`` where given) and :data:`PROTOCOL_DWELL`, 4
    significant digits; ``process_zone``: each with the Gent-Schultz process zone
    (:data:`PROTOCOL_PZ_V0`, :data:`PROTOCOL_PZ_XI`), MPL only."""
    rng = np.random.default_rng(seed)
    ranges = PROTOCOL_RANGES if mu is None else {**PROTOCOL_RANGES, "mu": mu}

    def log_uniform(lo, hi):
        return float(f"{math.exp(rng.uniform(math.log(lo), math.log(hi))):.4g}")

    out = []
    for _ in range(count):
        d = {"n": float(f"{rng.uniform(0.2, 1.9):.4g}")}
        d.update({name: log_uniform(lo, hi) for name, (lo, hi) in ranges.items()})
        d["dwell"] = 0.0 if rng.uniform() < 0.2 else log_uniform(*PROTOCOL_DWELL)
        d["dwell_hold"] = "depth" if rng.uniform() < 0.3 else "force"
        if process_zone:
            d.update(pz_law="gent-schultz", pz_v0=log_uniform(*PROTOCOL_PZ_V0),
                     pz_xi=float(f"{rng.uniform(*PROTOCOL_PZ_XI):.3g}"))
        else:
            d["material"] = "sls" if rng.uniform() < 0.2 else "mpl"
        d["model"] = "auto"
        out.append(d)
    return out


def protocol_config(process_zone: bool = False, tabor: bool = False) -> dict:
    """The sweep configuration of the protocol sample (balanced, :data:`BUDGET_S`), of its
    sample with a process zone, or (``tabor``) of its sample at large Tabor parameters."""
    name, count, seed = (("protocol_pz", PROTOCOL_PZ_COUNT, PROTOCOL_PZ_SEED) if process_zone
                         else ("protocol_tabor", PROTOCOL_TABOR_COUNT, PROTOCOL_TABOR_SEED)
                         if tabor else ("protocol", PROTOCOL_COUNT, PROTOCOL_SEED))
    what = ("with a test protocol and a process zone" if process_zone
            else f"with a test protocol at mu {PROTOCOL_TABOR_MU[0]:g}-{PROTOCOL_TABOR_MU[1]:g}"
            if tabor else "with a test protocol")
    return {"name": f"random-{name.replace('_', '-')}",
            "description": f"{count} scenes {what} (seed {seed}), model auto",
            "grid": protocol_sample(count, seed, process_zone,
                                    PROTOCOL_TABOR_MU if tabor else None),
            "numerics": {"preset": "balanced", "time_budget_s": BUDGET_S},
            "store": {"trajectories": False},
            "output": f"results/random/{name}.h5"}


def write_configs(count: int = 60, seed: int = 21) -> list[Path]:
    CONFIGS.mkdir(parents=True, exist_ok=True)
    paths = []
    for model in MODELS:
        path = CONFIGS / f"{model}.yaml"
        head = (f"# written by `python -m sweep.bench.random_sample configs --count {count} "
                f"--seed {seed}`; run by `make random-sample`\n")
        path.write_text(head + yaml.safe_dump(sample_config(count, seed, model),
                                              sort_keys=False, width=100))
        paths.append(path)
    for name, process_zone, tabor in (("protocol", False, False), ("protocol_pz", True, False),
                                      ("protocol_tabor", False, True)):
        path = CONFIGS / f"{name}.yaml"
        path.write_text("# written by `python -m sweep.bench.random_sample configs`; run by "
                        "`make random-sample`\n"
                        + yaml.safe_dump(protocol_config(process_zone, tabor), sort_keys=False,
                                         width=100))
        paths.append(path)
    return paths


def outcome(row) -> str:
    """"ok", "refused" (a physical refusal), "failed" or "error" (a bug) for one stored row."""
    if row["status"] in ("ok", "error"):
        return row["status"]
    return "refused" if is_physical_refusal(str(row["reason"])) else "failed"


def summarize(results: Path = RESULTS) -> dict:
    out = {}
    for model in SAMPLES:
        path = results / f"{model}.h5"
        if not path.exists():
            continue
        df = load(path)
        kinds = [outcome(r) for _, r in df.iterrows()]
        out[model] = {"scenes": len(df), **{k: kinds.count(k) for k in
                                             ("ok", "refused", "failed", "error")},
                      "answered_or_refused": (kinds.count("ok") + kinds.count("refused"))
                      / max(len(df), 1),
                      "model_used": df.model_used.value_counts().to_dict(),
                      "failures": [_failure(r) for (_, r), kind in zip(df.iterrows(), kinds)
                                   if kind in ("failed", "error")],
                      "scene_seconds": float(df.task_wall_s.sum()),
                      "sweep_wall_s": scene_span(df)}
    return out


#: a failed row's fields in the summary: the scene's, and a protocol scene's protocol (it has
#: no a0)
FAILURE_FIELDS = ("n", "k", "mu", "a0", "rate", "material")
PROTOCOL_FIELDS = ("approach_rate", "preload", "dwell", "dwell_hold")


def _failure(row) -> dict:
    def given(value):
        return value is not None and not (isinstance(value, float) and math.isnan(value))

    names = FAILURE_FIELDS + (PROTOCOL_FIELDS if given(row.get("preload")) else ())
    out = {name: row.get(name) for name in names if given(row.get(name))}
    out["reason"] = row["reason"]
    return out


def scene_span(df) -> float:
    """Seconds from the first scene's start to the last scene's end (``finished_at`` less
    ``task_wall_s``): the sweep's wall but for its start-up (the sum of the scenes' own walls
    is ``scene_seconds``; the two differ by the workers' parallelism)."""
    start = (df.finished_at - df.task_wall_s).min()
    return float(df.finished_at.max() - start)


def plot_map(results: Path = RESULTS) -> Path | None:
    """Left: the auto sample over (mu, rate), coloured by the model that answered (crosses:
    failed, squares: refused). Right: the crack-front model's measured differences from the
    BEM over mu, coloured by the amplification, and its envelope (measured_error) at
    amplification 1, 10, 100."""
    from ..analysis.plots import pyplot
    from ..engine.models import MODEL_ERRORS, amplification, measured_error

    path = results / "auto.h5"
    if not path.exists():
        return None
    plt = pyplot()
    df = load(path)
    fig, (ax, bx) = plt.subplots(1, 2, figsize=(12, 4.8))
    colours = {"bem": "tab:blue", "crack": "tab:orange", "elastic": "tab:green", "pb": "tab:red"}
    for model, colour in colours.items():
        d = df[(df.model_used == model) & (df.status == "ok")]
        if len(d):
            ax.scatter(d.mu, d.rate, c=colour, s=22, label=f"{model} ({len(d)})")
    kinds = [outcome(r) for _, r in df.iterrows()]
    for kind, marker in (("refused", "s"), ("failed", "x"), ("error", "X")):
        d = df[[k == kind for k in kinds]]
        if len(d):
            style = (dict(facecolors="none", edgecolors="k") if marker == "s" else dict(c="k"))
            ax.scatter(d.mu, d.rate, marker=marker, s=30, label=f"{kind} ({len(d)})", **style)
    ax.axvline(100.0, color="0.6", lw=0.8, ls="--")
    ax.set(xscale="log", yscale="log", xlabel="Tabor parameter mu",
           ylabel="unloading rate r tau0 / h0",
           title=f"model: auto, balanced, {len(df)} random scenes")
    ax.legend(fontsize=8, loc="lower left")
    doc = json.loads(MODEL_ERRORS.read_text())
    rows = [r for r in doc["rows"] if r["crack_vs_bem"] is not None]
    sc = bx.scatter([r["scene"]["mu"] for r in rows], [abs(r["crack_vs_bem"]) for r in rows],
                    c=[math.log10(amplification(r["crack_pull_off"])) for r in rows],
                    cmap="viridis", s=24)
    fig.colorbar(sc, ax=bx, label="log10 amplification P / 1.5")
    lo, hi = doc["crack"]["fit"]["mu_range"]
    mus = [lo * (1e4 / lo) ** (i / 80) for i in range(81)]
    for amp, ls in ((1.0, "-"), (10.0, "--"), (100.0, ":")):
        bx.plot(mus, [measured_error("crack", m, amp) for m in mus], "k", ls=ls, lw=1,
                label=f"measured_error, amplification {amp:g}")
    bx.axvline(hi, color="0.6", lw=0.8, ls="--")
    bx.set(xscale="log", yscale="log", xlabel="Tabor parameter mu",
           ylabel="|crack-front / BEM - 1|",
           title="crack-front model vs the BEM (make model-errors)")
    bx.legend(fontsize=8, loc="upper right")
    fig.tight_layout()
    out = results / "model_map.png"
    fig.savefig(out, dpi=120)
    plt.close(fig)
    return out


def _main(argv=None) -> int:
    p = argparse.ArgumentParser(prog="python -m sweep.bench.random_sample",
                                description="a random sample across the declared ranges")
    sub = p.add_subparsers(dest="command", required=True)
    c = sub.add_parser("configs",
                       help="write configs/random/{auto,bem,protocol,protocol_pz,protocol_tabor}.yaml")
    c.add_argument("--count", type=int, default=60)
    c.add_argument("--seed", type=int, default=21)
    sub.add_parser("summary", help="count the outcomes, draw the model map")
    args = p.parse_args(argv)
    if args.command == "configs":
        for path in write_configs(args.count, args.seed):
            print(path.relative_to(ROOT))
        return 0
    summary = summarize()
    RESULTS.mkdir(parents=True, exist_ok=True)
    (RESULTS / "summary.json").write_text(json.dumps(summary, indent=1, default=str))
    for model, s in summary.items():
        print(f"{model:5}: {s['scenes']} scenes: {s['ok']} ok, {s['refused']} physically "
              f"refused, {s['failed']} failed, {s['error']} internal errors "
              f"({100 * s['answered_or_refused']:.0f} % answered or refused); models used "
              f"{s['model_used']}")
        for f in s["failures"]:
            fields = " ".join(f"{k}={v:.4g}" if isinstance(v, float) else f"{k}={v}"
                              for k, v in f.items() if k != "reason")
            print(f"    failed: {fields}: {f['reason'][:110]}")
    out = plot_map()
    if out:
        print(out.relative_to(ROOT))
    return 1 if any(s["error"] for s in summary.values()) else 0


if __name__ == "__main__":
    raise SystemExit(_main())
