"""Benchmarks, one subcommand per kind, each writing a JSON report::

    python -m sweep.bench.benchmarks scheduler --out results/bench/scheduler.json

``scheduler``: parallel efficiency and per-scene overhead of the sweep engine. The grid is
``configs/smoke.yaml`` scaled up to ``--scenes`` scenes (its two n values times a finer
log-spaced rate axis over the same range). In one process, on one machine:

1. ``bare``: ``sweep.engine.bem.simulate`` called in a plain loop (after ``warm_up``);
2. ``j1``: ``run_sweep(jobs=1)`` (scheduler + store, in-process);
3. ``j2``: ``run_sweep(jobs=2)`` with fresh workers (the local backend's: forked where it
   forks, else loky's, their start included), then ``j2_warm`` with reused loky workers
   (``backend="loky"``, after one loky sweep started them);
4. optionally (``--cli``) the same with ``sweep run -j1`` / ``-j2`` subprocesses
   (each includes interpreter start-up, imports and the Numba cache load).

Reported: parallel efficiency ``t_j1 / (2 t_j2)`` and per-scene overhead
``(t_j1 - sum of bare simulate walls) / scenes``. ``store``: the cost of appending
``--rows`` rows and consolidating them (throughput of the results store).
"""
from __future__ import annotations

import dataclasses
import json
import math
import os
import platform
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass, field
from datetime import datetime, timezone
from pathlib import Path

import click
import numpy as np
import pandas as pd
import yaml
from joblib.externals.loky import get_reusable_executor
from numba import njit

from ..campaign.config import AXES, config_from_dict, load_config, scale_grid
from ..campaign.scheduler import run_sweep, start_group
from ..campaign.store import ResultStore, load
from ..engine import bem as solver
from ..engine import diskcache, initial, mesh, problem, tip_following
from ..engine.bem import simulate, warm_up
from ..engine import models
from ..kernels import solve as ks
from ..kernels.interface import lj_traction_and_stiffness
from ..kernels.jacobian import ZONE_IN, ZONE_OUT, crack_tip_index
from ..scene import PRESETS, Numerics, Scene
from .error_coverage import sample
from .plain_solver import plain_unload
from .tradeoff import (REFERENCE_OVERRIDES, REFERENCES, TRADEOFF_SCENES, VS_NUMPY_SCENES,
                       compute_reference, existing, load_references, reference_for,
                       relative_error, rederive_presets, to_numerics, write_tradeoff)

ROOT = Path(__file__).resolve().parents[2]


def _machine() -> dict:
    return {"cpus": os.cpu_count(), "platform": platform.platform(),
            "python": platform.python_version(),
            "date": datetime.now(timezone.utc).isoformat(timespec="seconds")}


def scaled_smoke(scenes: int = 40, base: str | Path | None = None):
    """configs/smoke.yaml with its rate axis refined so the grid has about ``scenes`` scenes."""
    cfg = load_config(base or ROOT / "configs" / "smoke.yaml")
    g = cfg.grids[0]
    per_rate = max(1, len(cfg.tasks()) // len(g["rate"]))
    n_rates = max(2, round(scenes / per_rate))
    lo, hi = np.log10(min(g["rate"])), np.log10(max(g["rate"]))
    rates = [float(r) for r in np.logspace(lo, hi, n_rates)]
    return scale_grid(cfg, "rate", rates)


def _fresh_workers() -> None:
    """New workers for the next sweep, with nothing in memory: the reusable loky executor shut
    down (its threads too: beside them the local backend would not fork), and this process's
    in-memory scene caches emptied (forked workers inherit them)."""
    try:
        get_reusable_executor().shutdown(wait=True)
    except Exception:  # pragma: no cover
        pass
    _clear_scene_caches()


def bench_scheduler(scenes: int = 40, jobs: int = 2, repeat: int = 3, cli: bool = False,
                    workdir: str | Path | None = None) -> dict:
    """Measure parallel efficiency and scheduler+store overhead per scene (see module doc).

    Each measurement is repeated ``repeat`` times, interleaved, and the minimum wall is
    used (robust to other load on the machine; the load averages are reported too).
    ``j{jobs}`` always starts fresh worker processes, like a new ``sweep run`` does;
    ``j{jobs}_warm`` reuses the workers of the previous call.
    """
    cfg = scaled_smoke(scenes)
    tasks = cfg.tasks()
    n = len(tasks)
    tmp = Path(workdir or tempfile.mkdtemp(prefix="bench-sched-"))
    tmp.mkdir(parents=True, exist_ok=True)
    load_before = os.getloadavg()
    solver.warm_up()
    simulate = solver.simulate
    simulate(tasks[0][1], cfg.numerics)   # first-call costs (caches) outside the timing

    def bare():
        walls, cpus, statuses = [], [], {}
        for _, scene in tasks:
            t, c = time.perf_counter(), time.process_time()
            res = simulate(scene, cfg.numerics)
            walls.append(time.perf_counter() - t)
            cpus.append(time.process_time() - c)
            statuses[res.status] = statuses.get(res.status, 0) + 1
        return walls, cpus, statuses

    def sweep(j, name, fresh_workers=True):
        if fresh_workers:
            _fresh_workers()
        t, c = time.perf_counter(), time.process_time()
        rep = run_sweep(cfg, jobs=j, out=tmp / f"{name}.h5", progress="none", resume=False,
                        backend="local" if fresh_workers else "loky")
        assert rep.ran == n
        return time.perf_counter() - t, time.process_time() - c

    samples = {"bare_sum": [], "bare_cpu_sum": [], "j1": [], "j1_cpu": [], "jN": [],
               "jN_warm": []}
    for r in range(repeat):
        walls, cpus, statuses = bare()
        samples["bare_sum"].append(float(np.sum(walls)))
        samples["bare_cpu_sum"].append(float(np.sum(cpus)))
        w, c = sweep(1, f"j1_{r}")
        samples["j1"].append(w)
        samples["j1_cpu"].append(c)
        samples["jN"].append(sweep(jobs, f"j{jobs}_{r}")[0])
        sweep(jobs, f"j{jobs}s_{r}", fresh_workers=False)          # starts the loky workers
        samples["jN_warm"].append(sweep(jobs, f"j{jobs}w_{r}", fresh_workers=False)[0])
    best = {k: min(v) for k, v in samples.items()}
    df = load(tmp / f"j{jobs}_{repeat - 1}.h5")
    out = {
        "kind": "scheduler",
        "machine": {**_machine(), "loadavg_before": load_before,
                    "loadavg_after": os.getloadavg()},
        "grid": {"base": "configs/smoke.yaml", "scenes": n,
                 "n": sorted({s.n for _, s in tasks}),
                 "rate": sorted({s.rate for _, s in tasks}),
                 "numerics": cfg.numerics.to_dict()},
        "status_counts": statuses,
        "repeat": repeat,
        "samples_s": samples,
        "bare_sum_s": best["bare_sum"],
        "bare_per_scene_s": best["bare_sum"] / n,
        "sweep_j1_s": best["j1"],
        f"sweep_j{jobs}_s": best["jN"],
        f"sweep_j{jobs}_warm_workers_s": best["jN_warm"],
        "parallel_efficiency": best["j1"] / (jobs * best["jN"]),
        "parallel_efficiency_warm_workers": best["j1"] / (jobs * best["jN_warm"]),
        "overhead_per_scene_s": (best["j1"] - best["bare_sum"]) / n,
        "overhead_pct_of_bare": 100.0 * (best["j1"] - best["bare_sum"]) / best["bare_sum"],
        "overhead_cpu_per_scene_s": (best["j1_cpu"] - best["bare_cpu_sum"]) / n,
        f"j{jobs}_task_cpu_over_wall": float(df.task_cpu_s.sum() / df.task_wall_s.sum()),
        "definitions": {
            "parallel_efficiency": f"min t(j1) / ({jobs} * min t(j{jobs})): run_sweep walls "
                                   f"in one process; every j{jobs} run starts fresh workers "
                                   f"(forked, or loky's with their imports and Numba cache "
                                   f"load; their start-up included)",
            "overhead_per_scene_s": "(min t(j1) - min sum of bare simulate walls) / scenes",
            "overhead_cpu_per_scene_s": "the same with CPU time of the process",
            "task_cpu_over_wall": "CPU/wall of the scenes in the workers: < 1 means the "
                                  "cores were shared with other load",
        },
    }
    if cli:
        cfg_path = tmp / "smoke_scaled.yaml"
        cfg_path.write_text(yaml.safe_dump({**cfg.to_dict(), "name": "smoke_scaled"},
                                           sort_keys=False))

        def timed_cli(j):
            cmd = [sys.executable, "-m", "sweep.cli", "run", str(cfg_path), "--progress",
                   "none", "--fresh", "-j", str(j), "--out", str(tmp / f"cli{j}.h5")]
            t = time.perf_counter()
            subprocess.run(cmd, check=True, capture_output=True, cwd=tmp)
            return time.perf_counter() - t, " ".join(["sweep"] + cmd[3:])
        c1 = min(timed_cli(1)[0] for _ in range(max(1, repeat // 2)))
        c2, cmd2 = min(timed_cli(jobs) for _ in range(max(1, repeat // 2)))
        out["cli"] = {"j1_s": c1, f"j{jobs}_s": c2, "parallel_efficiency": c1 / (jobs * c2),
                      "command": cmd2.replace(f"-j {jobs}", "-j {1,2}"),
                      "note": "each includes interpreter start-up, imports and cache load"}
    return out


def bench_store(rows: int = 1000, trajectories: bool = False, steps: int = 2000) -> dict:
    """Cost of ResultStore.append per row and of one consolidation with ``rows`` rows."""
    tmp = Path(tempfile.mkdtemp(prefix="bench-store-"))
    base = {"scene_id": "", "n": 0.8, "k": 0.1, "mu": 3.24, "rate": 1.0, "a0": 2.0,
            "delta0": None, "material": "mpl", "stop": "pulloff", "status": "ok",
            "reason": "", **{f"x{i}": 1.0 for i in range(25)}, "steps": 1}
    traj = {k: np.linspace(0, 1, steps) for k in ("t", "delta", "P", "a", "a_inner")}
    st = ResultStore(tmp / "s.h5", config_hash="b", n_scenes=rows, trajectories=trajectories,
                     template_row=base, interval=1e9)
    st.prepare()
    st.begin()
    t = time.perf_counter()
    for i in range(rows):
        st.append({**base, "scene_id": f"{i:016x}"}, traj if trajectories else None)
    t_append = time.perf_counter() - t
    t = time.perf_counter()
    st.consolidate()
    t_cons = time.perf_counter() - t
    st.finish()
    return {"kind": "store", "machine": _machine(), "rows": rows, "trajectories": trajectories,
            "trajectory_steps": steps if trajectories else 0,
            "append_per_row_s": t_append / rows, "consolidate_s": t_cons,
            "file_bytes": (tmp / "s.h5").stat().st_size}


# ------------------------------------------------------------------ single-scene solver

PAPER_SCENE = dict(n=0.8, k=0.1, mu=3.24, a0=3.61, rate=10**2.5)


class _KernelTimer:
    """Times the unloading kernel inside ``simulate`` (everything else is setup)."""

    def __enter__(self):
        self._solver = solver
        self._orig = solver.unload
        self.seconds = 0.0

        def timed(*args):
            t0 = time.perf_counter()
            out = self._orig(*args)
            self.seconds += time.perf_counter() - t0
            return out
        solver.unload = timed
        return self

    def __exit__(self, *exc):
        self._solver.unload = self._orig


def matvec_seconds(N: int, repeat: int = 2000) -> float:
    """Median wall time of one dense N x N matrix-vector product inside Numba (the floor
    of any dense BEM step: one evaluation of the deflection)."""
    @njit(cache=False)
    def loop(A, x, k):
        s = 0.0
        for _ in range(k):
            y = A @ x
            s += y[0]
        return s

    A = np.random.default_rng(0).random((N, N))
    x = np.random.default_rng(1).random(N)
    loop(A, x, 1)
    samples = []
    for _ in range(7):
        t0 = time.perf_counter()
        loop(A, x, repeat)
        samples.append((time.perf_counter() - t0) / repeat)
    return float(np.median(samples))


def _scene_run(scene, numerics, repeat: int) -> dict:
    best = None
    for _ in range(repeat):
        with _KernelTimer() as kt:
            res = simulate(scene, numerics)
        row = {"wall_s": res.wall_s, "kernel_s": kt.seconds, "status": res.status,
               "pull_off": res.pull_off, "crack_speed": res.crack_speed, "steps": res.steps,
               "newton_iterations": res.newton_iterations,
               "factorizations": res.factorizations, "prony_terms": res.prony_terms,
               "nodes": _nodes_used(res), "spacing": res.spacing}
        if best is None or row["wall_s"] < best["wall_s"]:
            best = row
    return best


def compile_seconds() -> dict:
    """Numba compile time: ``warm_up()`` in a fresh interpreter with an empty cache
    directory (cold), then again with the cache it left (cached)."""
    code = ("import time; t=time.perf_counter(); from sweep.engine.bem import warm_up; "
            "import_s=time.perf_counter()-t; w=warm_up(); print(import_s, w)")
    out = {}
    with tempfile.TemporaryDirectory() as cache:
        env = {**os.environ, "NUMBA_CACHE_DIR": cache}
        for label in ("cold", "cached"):
            t0 = time.perf_counter()
            proc = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True,
                                  text=True, check=True)
            imp, warm = map(float, proc.stdout.split())
            out[label] = {"process_s": time.perf_counter() - t0, "import_s": imp,
                          "warm_up_s": warm}
    return out


def _process_wall(argv: list[str], repeat: int) -> float:
    """The best wall time of ``repeat`` runs of a command as a whole process, s."""
    best = math.inf
    for _ in range(repeat):
        t0 = time.perf_counter()
        subprocess.run(argv, capture_output=True, check=True)
        best = min(best, time.perf_counter() - t0)
    return best


def bench_scene_process(repeat: int = 3) -> dict:
    """A single ``sweep scene`` (the paper scene, fast preset, Numba cache warm) as a whole
    process against ``python -c "import numpy, scipy"`` (issue 24 item 3: under 2x)."""
    sweep_cmd = str(Path(sys.executable).with_name("sweep"))
    scene = [sweep_cmd, "scene", *(f"--{k}={v}" for k, v in PAPER_SCENE.items()),
             "--preset", "fast"]
    subprocess.run(scene, capture_output=True, check=True)          # the cache filled
    imports = _process_wall([sys.executable, "-c", "import numpy, scipy"], repeat)
    # the floor of any process that runs a kernel: numba's import alone is about twice
    # that of numpy and scipy (docs/performance.md, "The first run")
    with_numba = _process_wall([sys.executable, "-c", "import numpy, scipy, numba"], repeat)
    one = _process_wall(scene, repeat)
    return {"scene_process_s": one, "import_numpy_scipy_s": imports, "ratio": one / imports,
            "import_numpy_scipy_numba_s": with_numba,
            "command": " ".join(["sweep", *scene[1:]]), "repeat": repeat}


def bench_scene(repeat: int = 3, compile_: bool = True) -> dict:
    """Issue-3 numbers: per-preset wall time of the paper's scene, time per step over one
    dense matvec, Prony vs exact speed-up at equal steps, compile time."""
    warm_up()
    scene = Scene(**PAPER_SCENE)
    report = {"kind": "scene", "machine": _machine(), "scene": PAPER_SCENE, "presets": {},
              "presets_at_500_nodes": {}}
    for name in PRESETS:
        for key, num in (("presets", Numerics.preset(name)),
                         ("presets_at_500_nodes", Numerics.preset(name, nodes=500))):
            row = _scene_run(scene, num, repeat)
            tmv = matvec_seconds(row["nodes"])
            row["matvec_s"] = tmv
            row["step_s"] = row["kernel_s"] / max(row["steps"], 1)
            row["step_over_matvec"] = row["step_s"] / tmv
            report[key][name] = row
    # Prony vs exact hereditary integral on the same step sequence (no step control)
    small = Scene(n=0.8, k=0.1, mu=3.24, a0=2.0, rate=100.0)
    pe = {}
    for nodes, step in ((100, 0.05), (200, 0.025)):   # about 170 and 340 steps
        num = dict(nodes=nodes, step=step, da_max=1e6, tol=1e-9)
        prony = _scene_run(small, Numerics(**num, prony_rtol=1e-4), 1)
        exact = _scene_run(small, Numerics(**num, exact=True), 1)
        pe[f"{nodes} nodes, step {step} h0"] = {"prony": prony, "exact": exact,
                          "speedup": exact["wall_s"] / prony["wall_s"],
                          "pull_off_rel_diff": prony["pull_off"] / exact["pull_off"] - 1}
    report["prony_vs_exact"] = pe
    if compile_:
        report["compile"] = compile_seconds()
    return report


#: the independent solver's values, kept with the tests (tests/data/README.md says where from)
REFERENCE_YAML = ROOT / "tests" / "data" / "independent_solutions.yaml"


def bench_presets(repeat: int = 1) -> dict:
    """Speed/accuracy of the presets: error against the independent solver's values
    (shared/reference/independent_solutions.yaml) and cost, per case and preset. The BEM's
    rows drop the Lennard-Jones tail beyond the mesh (``Numerics.lj_tail`` False), as the
    references do; the elastic row runs the elastic branch, which has it."""
    warm_up()
    ref = yaml.safe_load(REFERENCE_YAML.read_text())
    rows = []
    for case in ref["viscoelastic"]:
        scene = Scene(**case["scene"])
        for name in PRESETS:
            # like for like: the references drop the Lennard-Jones tail beyond their meshes
            r = _scene_run(scene, Numerics.preset(name, lj_tail=False), repeat)
            rows.append({"case": case["name"], "preset": name, **r,
                         "pull_off_ref": case["pull_off"],
                         "pull_off_rel_err": r["pull_off"] / case["pull_off"] - 1,
                         "crack_speed_ref": case["crack_speed"],
                         "crack_speed_rel_err": r["crack_speed"] / case["crack_speed"] - 1})
    # the elastic reference (k = 1, quasi-static): where coarse meshes cost the most
    el = ref["elastic"][0]
    scene = Scene(n=1.0, k=1.0, mu=el["mu"], a0=2.0, rate=1.0)
    for name in PRESETS:
        r = _scene_run(scene, Numerics.preset(name), repeat)
        rows.append({"case": f"elastic mu={el['mu']}", "preset": name, **r,
                     "pull_off_ref": el["pull_off"],
                     "pull_off_rel_err": r["pull_off"] / el["pull_off"] - 1,
                     "crack_speed_ref": None, "crack_speed_rel_err": None})
    return {"kind": "presets", "machine": _machine(), "rows": rows}


def bench_convergence(mu: float = 6.0, nodes=(1000, 1500, 2000), domain: float = 5.0) -> dict:
    """Mesh convergence of the elastic pull-off at a large Tabor parameter (lattice trapping
    at coarse spacing), against the independent solver's value for that mu if it has one."""
    ref = yaml.safe_load(REFERENCE_YAML.read_text()) if REFERENCE_YAML.exists() else {}
    ref_po = next((e["pull_off"] for e in ref.get("elastic", []) if e["mu"] == mu), None)
    rows = []
    for N in nodes:
        r = _scene_run(Scene(n=1.0, k=1.0, mu=mu, a0=2.0, rate=1.0),
                       Numerics(nodes=N, domain=domain, step=0.05, tol=1e-9), 1)
        r["domain"] = domain
        rows.append(r)
    return {"kind": "convergence", "machine": _machine(), "mu": mu, "reference_pull_off": ref_po,
            "rows": rows}


# ------------------------------------------------------------------ make bench: bench.json

#: the external BEM data set's ranges (issue 33 item 5; log-uniform in each): Tabor parameter,
#: k = E0/Einf, MPL exponent, loading rate r-hat. a0 (a_ref): the data set starts each scene
#: from a given contact radius; 1-10 a_ref is where the BEM finishes its scenes (below 1,
#: scenes start near the JKR fold; far above 10 the contact is the crack-front model's)
DATASET_RANGES = {"mu": (0.01, 3.24), "k": (1e-4, 0.5), "n": (0.2, 2.0), "rate": (1e-2, 1e12),
                  "a0": (1.0, 10.0)}


@dataclass(frozen=True)
class BenchPlan:
    """What ``bench_all`` measures (the defaults are ``make bench``; :meth:`tiny` is a
    seconds-long configuration for tests of the harness)."""

    matvec_nodes: tuple = (250, 500, 1000)
    matvec_scene: dict = field(default_factory=lambda: dict(PAPER_SCENE))
    matvec_preset: str = "balanced"
    prony_steps: tuple = (500, 2000, 8000)
    prony_scene: dict = field(default_factory=lambda: dict(n=0.8, k=0.1, mu=3.24, a0=2.0,
                                                           rate=100.0))
    prony_numerics: dict = field(default_factory=lambda: dict(nodes=100, da_max=1e6,
                                                              tol=1e-9, prony_rtol=1e-4))
    compile: bool = True
    campaign: str = "configs/threshold.yaml"
    #: every 5th threshold scene (188): at the engine of session 17 every 20th (47 scenes)
    #: ran in 1-2 s, too short for a parallel speed-up (dispatch and one 0.65 s scene)
    campaign_stride: int = 5
    jobs: int = 2
    #: the accurate campaign of issue 24 (480 scenes at the balanced preset), run whole
    balanced_campaign: str = "configs/threshold_balanced.yaml"
    scale_config: str = "configs/scale.yaml"
    scale_sample: int = 80
    scale_seed: int = 0
    vs_numpy_scenes: dict = field(default_factory=lambda: dict(VS_NUMPY_SCENES))
    engine_numerics: dict = field(default_factory=lambda: {
        "fast": {"preset": "fast"}, "balanced": {"preset": "balanced"}})
    #: the plain solver's (N, step) runs in order of cost; the denser the ladder, the
    #: tighter the bound ``ratio`` (intermediate rungs added in session 16: 200, 300, 500, 750)
    plain_ladder: tuple = ((150, 0.25), (200, 0.25), (250, 0.25), (250, 0.1), (300, 0.1),
                           (400, 0.1), (500, 0.1), (600, 0.1), (500, 0.05), (600, 0.05),
                           (750, 0.05), (900, 0.05))
    plain_time_limit_s: float = 90.0
    reference_fallback: dict | None = None
    repeat: int = 2
    #: a campaign of the external BEM data set's kind (issue 33 item 5): a seeded sample of
    #: its ranges (:data:`DATASET_RANGES`), model bem, at an accuracy asked for
    dataset_scenes: int = 200
    dataset_seed: int = 0
    dataset_ranges: dict = field(default_factory=lambda: dict(DATASET_RANGES))
    dataset_numerics: dict = field(default_factory=lambda: {"pull_off_rtol": 0.01})
    #: where the first run's time goes: every dataset_profile_stride-th scene of the sample
    #: run again in this process, from an empty disk cache, its phases timed. The whole
    #: sample: a subset grows the unit influence matrix less far (every 4th scene: 0.5 s of
    #: influence matrices where the whole sample takes 5 s)
    dataset_profile_stride: int = 1

    @classmethod
    def tiny(cls) -> "BenchPlan":
        small = dict(n=0.8, k=0.5, mu=3.24, delta0=1.0, rate=10.0)
        once = dict(mesh="uniform", pull_off_rtol=0.0)   # one solve per scene, where they exist
        return cls(matvec_nodes=(60,), matvec_scene=dict(n=0.8, k=0.5, mu=3.24, a0=1.2,
                                                         rate=10.0),
                   matvec_preset="fast", prony_steps=(20,),
                   prony_scene=dict(n=0.8, k=0.5, mu=3.24, a0=1.2, rate=10.0),
                   prony_numerics=dict(nodes=60, domain=2.5, da_max=1e6, tol=1e-8,
                                       prony_rtol=1e-2),
                   compile=False, campaign="configs/smoke.yaml",
                   balanced_campaign="configs/smoke.yaml",
                   campaign_stride=4, jobs=1, scale_config="configs/smoke.yaml",
                   scale_sample=3,
                   vs_numpy_scenes={"tiny": small},
                   engine_numerics={"fast": existing(dict(nodes=60, domain=2.5, step=0.5,
                                                          prony_rtol=1e-2, **once))},
                   plain_ladder=((60, 0.5),), plain_time_limit_s=30.0,
                   reference_fallback=existing(dict(nodes=80, domain=2.5, step=0.25, **once)),
                   repeat=1, dataset_scenes=3,
                   dataset_ranges=dict(DATASET_RANGES, mu=(0.05, 0.5), a0=(1.0, 2.0)),
                   dataset_numerics={"pull_off_rtol": 0.03}, dataset_profile_stride=2)


def _numerics(overrides: dict):
    return to_numerics(overrides)


def step_cost(scene, numerics, repeat: int = 2) -> dict:
    """Marginal wall time per time step: a full run and the same run cut at 10 steps
    (``max_steps=10``, so setup and the first steps are alike), differenced.

    Uses only the public API (``Result.wall_s``, ``Result.steps``): setup (mesh, Prony
    series, relaxed start) cancels in the difference.
    """
    full = min((simulate(scene, numerics) for _ in range(repeat)), key=lambda r: r.wall_s)
    cut_num = dataclasses.replace(numerics, max_steps=10)
    cut = min((simulate(scene, cut_num) for _ in range(repeat)), key=lambda r: r.wall_s)
    steps = full.steps - cut.steps
    per_step = (full.wall_s - cut.wall_s) / steps if steps > 0 else math.nan
    return {"status": full.status, "steps": full.steps, "wall_s": full.wall_s,
            "wall_10_steps_s": cut.wall_s, "step_s": per_step,
            "newton_iterations_per_step": full.newton_iterations / max(full.steps, 1),
            "nodes": _nodes_used(full)}


def _nodes_used(res) -> int:
    """Mesh nodes of a result (a graded engine may report them; else Numerics.nodes)."""
    for name in ("nodes", "nodes_used", "mesh_nodes"):
        v = getattr(res, name, None)
        if isinstance(v, (int, np.integer)) and v > 0:
            return int(v)
    return int(res.numerics.nodes)


def kernel_counters(scene, numerics) -> dict:
    """Counters of the unloading kernel on one run (``kernels.solve`` STAT_*), per step:
    residual evaluations (one N x N mat-vec each), Newton iterations, solves ended on the
    predicted residual (``kernels.solve.PREDICTED_RESIDUAL``), refactorizations of the
    crack-tip zone's Schur complement (``zone_refreshes``), factorizations of the contact
    (with the reason of the refactorizations) and the mean size of the interacting set
    |S|/N."""
    captured = {}
    orig = solver.unload

    def capture(*args):
        out = orig(*args)
        captured["stats"] = args[-1].copy()
        return out
    solver.unload = capture
    try:
        res = solver.simulate(scene, numerics)
    finally:
        solver.unload = orig
    st, steps, N = captured["stats"], max(res.steps, 1), _nodes_used(res)
    return {"residual_matvecs_per_step": st[ks.STAT_RESIDUALS] / steps,
            "newton_iterations_per_step": st[ks.STAT_ITER] / steps,
            "zone_refreshes_per_step": st[ks.STAT_ZONE] / steps,
            "predicted_solves_per_step": st[ks.STAT_PREDICTED] / steps,
            "factorizations": int(st[ks.STAT_FACTOR]),
            "refactorizations": {"tip_left_zone": int(st[ks.STAT_REFACTOR_ZONE]),
                                 "slow_contraction": int(st[ks.STAT_REFACTOR_SLOW]),
                                 "line_search": int(st[ks.STAT_REFACTOR_LINESEARCH])},
            "steps_per_factorization": steps / max(st[ks.STAT_FACTOR], 1),
            "subset_fraction": st[ks.STAT_SUBSET] / max(st[ks.STAT_FACTOR], 1) / N,
            "note": "counters include the relaxed start's elastic solves when not cached"}


def compare_results(before, after) -> dict:
    """Agreement of two results files of the same scenes (two engine versions, say): scenes
    in both, status changes, and over the scenes ``ok`` in both the relative differences
    |after / before - 1| of the pull-off and the crack speed (max and median), with the sums
    of the scenes' wall times."""
    a = load(before).set_index("scene_id")
    b = load(after).set_index("scene_id")
    common = a.index.intersection(b.index)
    only = {"only_before": int(len(a) - common.size), "only_after": int(len(b) - common.size)}
    a, b = a.loc[common], b.loc[common]
    ok = (a.status == "ok") & (b.status == "ok")
    out = {"scenes": int(common.size), **only,
           "status_changed": int((a.status != b.status).sum()), "ok_in_both": int(ok.sum()),
           "wall_s_sum": {"before": float(a.wall_s.sum()), "after": float(b.wall_s.sum())}}
    for column in ("pull_off", "crack_speed"):
        rel = (b[column][ok] / a[column][ok] - 1.0).abs()
        out[column] = {"max_rel_diff": float(rel.max()), "median_rel_diff": float(rel.median())}
    return out


def newton_diagnosis(scene, numerics, at_step: int = 300, ahead: int = 10) -> dict:
    """Why Newton costs what it does on one scene: the kernel counters of the whole run
    (:func:`kernel_counters`) and, from the accepted states at steps ``at_step`` .. +
    ``ahead`` (runs cut there by ``max_steps``): the spectral radius of the chord map
    I - J_used^-1 J after 1 and ``ahead`` steps, with the crack-tip zone exact and the rest
    as factorized at ``at_step`` (dense eigenvalues: the staleness of the Jacobian), and the
    cubic predictor's error |h_pred - h| / h0 (max over the nodes, where, and median) for
    each of the last steps (the distance Newton starts from)."""
    captured = {}
    orig = solver.unload

    def capture(*args):
        out = orig(*args)
        captured.setdefault("calls", []).append((args, out[1]))
        return out
    steps = list(range(at_step - 3, at_step + ahead + 1))
    gaps, times = {}, {}
    solver.unload = capture
    try:
        for k in steps:
            captured.clear()
            solver.simulate(scene, dataclasses.replace(numerics, max_steps=k))
            # the run's own kernel call (an error-indicator solve on a cheaper mesh may follow)
            args, n = captured["calls"][0]
            records = args[4]                # kernels.solve.Records
            gaps[k], times[k] = records.h.copy(), float(records.t[n - 1])
    finally:
        solver.unload = orig
    A, h0, c = args[0].A, args[1].h0, args[1].c     # MeshArrays, Physics
    N = A.shape[0]

    def stiffness(h):
        sig, d = np.empty(N), np.empty(N)
        lj_traction_and_stiffness(h, h0, c, sig, d)
        return d
    d0 = stiffness(gaps[at_step])
    tip = crack_tip_index(d0, np.zeros(d0.size))
    lo, hi = max(tip - ZONE_IN, 0), min(tip + ZONE_OUT, N)
    chord = {}
    for k in (at_step + 1, at_step + ahead):
        d1 = stiffness(gaps[k])
        used = d0.copy()
        used[lo:hi] = d1[lo:hi]
        J_used, J = np.eye(N) - A * used[None, :], np.eye(N) - A * d1[None, :]
        M = np.eye(N) - np.linalg.solve(J_used, J)
        chord[str(k - at_step)] = float(np.max(np.abs(np.linalg.eigvals(M))))
    predictor = []
    for k in steps[4:]:
        t = [times[k - 4 + i] for i in range(4)]
        pred = np.zeros(N)
        for i in range(4):
            weight = 1.0
            for j in range(4):
                if j != i:
                    weight *= (times[k] - t[j]) / (t[i] - t[j])
            pred += weight * gaps[k - 4 + i]
        err = np.abs(pred - gaps[k]) / h0
        predictor.append({"step": k, "dt": float(times[k] - t[-1]), "max": float(err.max()),
                          "node": int(np.argmax(err)), "tip_node": int(tip),
                          "median": float(np.median(err))})
    return {"scene": dataclasses.asdict(scene), "nodes": N,
            "counters": kernel_counters(scene, numerics),
            "zone": [int(lo), int(hi)], "chord_spectral_radius_after_steps": chord,
            "cubic_predictor_error_h0": predictor}


def bench_step_over_matvec(plan: BenchPlan) -> dict:
    """Time per step over the time of one dense N x N mat-vec at the mesh's N, with the
    kernel's counters (:func:`kernel_counters`)."""
    scene = Scene(**plan.matvec_scene)
    out = {}
    for N in plan.matvec_nodes:
        num = Numerics.preset(plan.matvec_preset, **existing(dict(nodes=N, pull_off_rtol=0.0)))
        row = step_cost(scene, num, plan.repeat)
        row["matvec_s"] = matvec_seconds(row["nodes"])
        row["ratio"] = row["step_s"] / row["matvec_s"]
        row["counters"] = kernel_counters(scene, num)
        out[str(N)] = row
    return out


def bench_prony_speedup(plan: BenchPlan) -> dict:
    """Prony recursion vs exact convolution on the same scene and (about) the same steps.

    The step is set so that the run takes the requested number of steps (the radius
    control is off: ``da_max`` huge, so both integrators take the same fixed steps; uniform
    mesh, no second error-check solve). The
    speed-up is the ratio of wall time per step (whole runs, setup included).
    """
    scene = Scene(**plan.prony_scene)
    base = existing({"mesh": "uniform", "pull_off_rtol": 0.0, **plan.prony_numerics})
    probe = simulate(scene, Numerics(**base, step=0.1))
    travel = probe.steps * 0.1                     # indentation to pull-off, units of h0
    out = {}
    for target in plan.prony_steps:
        step = travel / target
        num = Numerics(**base, step=step, min_step=min(1e-4, step))
        prony = min((simulate(scene, num) for _ in range(plan.repeat)), key=lambda r: r.wall_s)
        exact = simulate(scene, dataclasses.replace(num, exact=True))
        out[str(target)] = {
            "step_h0": step, "prony_steps": prony.steps, "exact_steps": exact.steps,
            "prony_wall_s": prony.wall_s, "exact_wall_s": exact.wall_s,
            "prony_status": prony.status, "exact_status": exact.status,
            "pull_off_rel_diff": prony.pull_off / exact.pull_off - 1.0,
            "speedup": (exact.wall_s / max(exact.steps, 1)) / (prony.wall_s / max(prony.steps, 1))}
    return out


def _listed(config, scenes, name: str):
    """A config with the numerics of ``config`` whose grid lists ``scenes`` one by one."""
    grid = [{k: v for k, v in s.to_dict().items() if k in AXES and v is not None}
            for s in scenes]
    return config_from_dict({**config.to_dict(), "grid": grid, "name": name})


def campaign_subset(config, stride: int):
    """Every ``stride``-th scene of a sweep config (its task order), as a config whose grid
    lists them one by one: a sample with the campaign's own mix of n, a0 and rate."""
    picked = [scene for _, scene in config.tasks()[::max(int(stride), 1)]]
    return _listed(config, picked, f"{config.name}_every{stride}")


def campaign_sample(config, size: int, seed: int = 0):
    """A seeded random sample of ``size`` scenes of a sweep config (without replacement),
    as a config listing them: unlike a stride, it cannot alias with the grid's axes."""
    tasks = config.tasks()
    rng = np.random.default_rng(seed)
    pick = np.sort(rng.choice(len(tasks), size=min(int(size), len(tasks)), replace=False))
    return _listed(config, [tasks[i][1] for i in pick], f"{config.name}_sample{len(pick)}")


def _clear_scene_caches() -> None:
    """Empty this process's per-scene caches (relaxed starts, Prony series, meshes)."""
    initial.clear_relaxed_cache()
    problem.prony_series.cache_clear()
    problem.derive.cache_clear()
    mesh.clear_mesh_cache()


class _fresh_disk_cache:
    """Within: an empty on-disk cache (:mod:`sweep.engine.diskcache`, a new temporary directory)
    and empty in-memory scene caches, with workers started afresh so that they see it:
    what a first run on a new machine pays. Restores the previous cache directory."""

    def __enter__(self):
        self._env = os.environ.get(diskcache.CACHE_ENV)
        os.environ[diskcache.CACHE_ENV] = tempfile.mkdtemp(prefix="bench-cache-")
        self._unit = mesh.set_unit_influence(None)
        _clear_scene_caches()
        _fresh_workers()
        return self

    def __exit__(self, *exc):
        if self._env is None:
            os.environ.pop(diskcache.CACHE_ENV, None)
        else:
            os.environ[diskcache.CACHE_ENV] = self._env
        mesh.set_unit_influence(self._unit)
        _clear_scene_caches()
        _fresh_workers()


def bench_scale(plan: "BenchPlan") -> dict:
    """The issue's scale: minutes for the whole of ``plan.scale_config`` (10,640 scenes over
    the paper's ranges) at -j{jobs}, from a seeded random sample of ``plan.scale_sample``
    scenes run with the config's own numerics.

    Two figures. ``minutes_sample_rate``: the sample's -j{jobs} wall scaled to the grid, an
    upper bound, since nearly every scene of a random sample pays its own relaxed start and
    Prony fit, which the whole grid shares (one relaxed start per (k, mu, preload) group and
    worker: 152 scenes a group in configs/scale.yaml). ``minutes_estimate``: the same sample
    run twice in this process at -j1, with empty caches (cold) and again (warm: every set-up
    cached); the grid costs its scenes at the warm rate plus one cold set-up per start group
    and worker, divided by the parallel speed-up measured on the sample (-j1 cold / -j{jobs}
    cold). The sample's statuses are reported with it: a failed scene costs its time too.
    """
    cfg = load_config_path(plan.scale_config)
    sample = campaign_sample(cfg, plan.scale_sample, plan.scale_seed)
    scenes = [s for _, s in sample.tasks()]
    tmp = Path(tempfile.mkdtemp(prefix="bench-scale-"))
    with _fresh_disk_cache():
        t = time.perf_counter()
        rep = run_sweep(sample, jobs=plan.jobs, out=tmp / "sample.h5", progress="none",
                        resume=False)
        wall = time.perf_counter() - t
    df = load(tmp / "sample.h5")
    seq = {}
    with _fresh_disk_cache():
        for label in ("cold", "warm"):
            t = time.perf_counter()
            for scene in scenes:
                models.simulate(scene, sample.numerics)
            seq[label] = time.perf_counter() - t
    n = len(scenes)
    total = len(cfg.tasks())
    groups_sample = len({start_group(s) for s in scenes})
    groups_full = len({start_group(s) for _, s in cfg.tasks()})
    setup_per_group = max(seq["cold"] - seq["warm"], 0.0) / max(groups_sample, 1)
    speedup = seq["cold"] / wall if wall > 0 else float("nan")
    cpu_full = total * seq["warm"] / max(n, 1) + groups_full * plan.jobs * setup_per_group
    slow = df.sort_values("wall_s", ascending=False).head(5)
    return {"config": plan.scale_config, "scenes": total, "sample": n, "seed": plan.scale_seed,
            "jobs": plan.jobs, "ran": rep.ran, "wall_s": wall,
            "status_counts": {str(k): int(v) for k, v in df.status.value_counts().items()},
            "scene_wall_s": {"mean": float(df.wall_s.mean()), "median": float(df.wall_s.median()),
                             "max": float(df.wall_s.max())},
            "slowest": [{key: (None if pd.isna(r[key]) else
                               (str(r[key]) if key == "status" else float(r[key])))
                         for key in ("n", "k", "rate", "a0", "delta0", "wall_s", "status")}
                        for r in slow.to_dict("records")],
            "sequential_s": seq, "start_groups": {"sample": groups_sample, "grid": groups_full},
            "setup_s_per_group": setup_per_group, "sample_parallel_speedup": speedup,
            "minutes_sample_rate": total * wall / max(n, 1) / 60.0,
            "minutes_estimate": cpu_full / speedup / 60.0,
            "loadavg": os.getloadavg()}


def bench_balanced_campaign(plan: "BenchPlan") -> dict:
    """The whole of ``plan.balanced_campaign`` (the version-0.1 threshold grid at the balanced
    preset, 480 scenes: issue 24 item 1, under 60 s on 2 cores) run by ``run_sweep`` at
    -j{jobs}, as a user runs it: kernels compiled, the on-disk caches (unit influence
    matrix, Prony series) as this machine has them, fresh workers. Reports the wall, the
    statuses, the scene walls summed and per a0, and the meshes the scenes ran on."""
    cfg = load_config_path(plan.balanced_campaign)
    tmp = Path(tempfile.mkdtemp(prefix="bench-balanced-"))
    warm_up()
    _fresh_workers()
    t = time.perf_counter()
    rep = run_sweep(cfg, jobs=plan.jobs, out=tmp / "runs.h5", progress="none", resume=False)
    wall = time.perf_counter() - t
    df = load(tmp / "runs.h5")
    tip = df.reason.fillna("").str.contains("tip-following mesh")
    by_a0 = df.groupby("a0").wall_s.sum()
    return {"config": plan.balanced_campaign, "scenes": int(len(df)), "ran": rep.ran,
            "jobs": plan.jobs, "wall_s": wall,
            "status_counts": {str(k): int(v) for k, v in df.status.value_counts().items()},
            "scene_wall_s_sum": float(df.wall_s.sum()),
            "scene_wall_s_by_a0": {f"{a0:g}": float(w) for a0, w in by_a0.items()},
            "tip_following_scenes": int(tip.sum()),
            "max_nodes_used": int(df.nodes_used.max()),
            "loadavg": os.getloadavg()}


def load_config_path(path: str):
    """A sweep config by path relative to the repository root (or absolute)."""
    p = Path(path)
    return load_config(p if p.is_absolute() else ROOT / p)


def bench_campaign(plan: BenchPlan) -> dict:
    """Scenes per minute of the campaign's numerics on a sample of its grid (every
    ``campaign_stride``-th scene), at -j1 and -j{jobs} with warm loky workers (a first,
    untimed sweep of the sample's first scenes starts them and loads their caches; loky's,
    which live from one sweep to the next, where forked workers would inherit the -j1 run's
    in-memory caches from this process).

    Both timed runs start from the same state: an on-disk cache filled by a first run of
    the sample (``wall_s.first_j1``, which fits every Prony series once) and empty
    in-memory caches (relaxed starts, meshes) in every process."""
    cfg = load_config_path(plan.campaign)
    sub_cfg = campaign_subset(cfg, plan.campaign_stride)
    tasks = sub_cfg.tasks()
    n = len(tasks)
    warm_up()
    tmp = Path(tempfile.mkdtemp(prefix="bench-campaign-"))
    walls = {}
    with _fresh_disk_cache():
        # a first run fills the on-disk caches (Prony series, unit influence matrix), as
        # a user's first sweep of a campaign does; both timed runs then start from them
        t = time.perf_counter()
        rep = run_sweep(sub_cfg, jobs=1, out=tmp / "first.h5", progress="none", resume=False)
        walls["first_j1"] = time.perf_counter() - t
        _clear_scene_caches()
        t = time.perf_counter()
        rep = run_sweep(sub_cfg, jobs=1, out=tmp / "j1.h5", progress="none", resume=False)
        walls["j1"] = time.perf_counter() - t
        if plan.jobs > 1:
            data = sub_cfg.to_dict()
            warm = config_from_dict({**data, "grid": data["grid"][:2 * plan.jobs],
                                     "name": "warm"})
            run_sweep(warm, jobs=plan.jobs, out=tmp / "warm.h5", progress="none",
                      resume=False, backend="loky")
        t = time.perf_counter()
        repj = run_sweep(sub_cfg, jobs=plan.jobs, out=tmp / "jN.h5", progress="none",
                         resume=False, backend="loky")
        walls[f"j{plan.jobs}"] = time.perf_counter() - t
        # the same again in the same processes: every per-process cache (relaxed starts,
        # meshes) now warm on both sides, the steady state of a long sweep
        t = time.perf_counter()
        run_sweep(sub_cfg, jobs=1, out=tmp / "j1b.h5", progress="none", resume=False)
        walls["j1_warm_caches"] = time.perf_counter() - t
        t = time.perf_counter()
        run_sweep(sub_cfg, jobs=plan.jobs, out=tmp / "jNb.h5", progress="none", resume=False,
                  backend="loky")
        walls[f"j{plan.jobs}_warm_caches"] = time.perf_counter() - t
    df = load(tmp / "jN.h5")
    statuses = df.status.value_counts().to_dict()
    return {"config": plan.campaign, "stride": plan.campaign_stride, "scenes": n,
            "campaign_scenes": len(cfg.tasks()),
            "numerics": sub_cfg.numerics.to_dict(), "ran": [rep.ran, repj.ran],
            "status_counts": {str(k): int(v) for k, v in statuses.items()},
            "scene_wall_s": {"mean": float(df.wall_s.mean()), "max": float(df.wall_s.max())},
            "wall_s": walls, "jobs": plan.jobs,
            "scenes_per_minute_j1": 60.0 * n / walls["j1"],
            f"scenes_per_minute_j{plan.jobs}": 60.0 * n / walls[f"j{plan.jobs}"],
            "campaign_minutes_estimate": len(cfg.tasks()) * walls[f"j{plan.jobs}"] / n / 60.0,
            "parallel_speedup": walls["j1"] / walls[f"j{plan.jobs}"],
            "parallel_speedup_warm_caches": (walls["j1_warm_caches"]
                                             / walls[f"j{plan.jobs}_warm_caches"]),
            "loadavg": os.getloadavg()}


def _bracket(engine_err: float, plain_rows: list[dict]) -> dict:
    """The plain runs on either side of the engine's error: the most accurate one whose
    error is still >= the engine's (equal or worse: its time is a lower bound of what the
    plain solver needs for the engine's accuracy) and the cheapest one at least as accurate."""
    ok = [r for r in plain_rows if r["status"] == "ok" and math.isfinite(r["err_pull_off"])]
    worse = [r for r in ok if r["err_pull_off"] >= engine_err]
    better = [r for r in ok if r["err_pull_off"] < engine_err]
    return {"equal_or_worse": min(worse, key=lambda r: r["err_pull_off"]) if worse else None,
            "better": min(better, key=lambda r: r["wall_s"]) if better else None}


def plain_time_at(engine_err: float, plain_rows: list[dict]) -> float | None:
    """The plain solver's time at exactly the engine's error, interpolated (log time linear
    in log error) between the two neighbouring runs of its time/error frontier (the runs
    that no cheaper run beats in accuracy); None when no run of the ladder is at least as
    accurate, or none is as inaccurate (no bracket, nothing to interpolate)."""
    ok = sorted((r for r in plain_rows if r["status"] == "ok"
                 and math.isfinite(r["err_pull_off"]) and r["err_pull_off"] > 0.0),
                key=lambda r: r["wall_s"])
    frontier = []
    for r in ok:
        if not frontier or r["err_pull_off"] < frontier[-1]["err_pull_off"]:
            frontier.append(r)
    for lo, hi in zip(frontier, frontier[1:]):        # lo cheaper and less accurate
        e1, e2 = lo["err_pull_off"], hi["err_pull_off"]
        if e1 >= engine_err >= e2:
            if e1 == e2:
                return lo["wall_s"]
            f = math.log(e1 / engine_err) / math.log(e1 / e2)
            return math.exp(math.log(lo["wall_s"]) + f * math.log(hi["wall_s"] / lo["wall_s"]))
    return None


def bench_vs_numpy(plan: BenchPlan, progress=print) -> dict:
    """Engine vs the plain numpy solver (:mod:`sweep.bench.plain_solver`) on the issue's scenes.

    Errors are relative pull-off errors against the stored converged reference of each scene
    (see :mod:`sweep.bench.tradeoff`). The engine's time is the best of ``repeat`` calls in this
    process (per-scene caches warm, as in a sweep); its first call is reported too. The plain
    solver climbs its ladder of (N, step) until it is more accurate than every engine
    configuration (or a run exceeds ``plain_time_limit_s``). ``ratio`` = plain time at equal
    or worse error / engine time: a lower bound of the speed-up at equal accuracy;
    ``ratio_better`` uses the cheapest plain run at least as accurate (an upper estimate);
    ``ratio_interpolated`` the plain time interpolated to the engine's error on the plain
    solver's time/error frontier (:func:`plain_time_at`), the estimate at equal accuracy.
    """
    refs = load_references()
    fallback = Numerics(**plan.reference_fallback) if plan.reference_fallback else None
    out = {}
    for name, sdict in plan.vs_numpy_scenes.items():
        scene = Scene(**sdict)
        ref = reference_for(name, sdict, refs, fallback)
        engine = {}
        for label, ov in plan.engine_numerics.items():
            num = _numerics(ov)
            runs = [simulate(scene, num) for _ in range(max(plan.repeat, 1))]
            best = min(runs, key=lambda r: r.wall_s)
            engine[label] = {"wall_s": best.wall_s, "first_call_wall_s": runs[0].wall_s,
                             "status": best.status, "pull_off": best.pull_off,
                             "err_pull_off": relative_error(best.pull_off, ref["pull_off"]),
                             "steps": best.steps, "nodes": _nodes_used(best)}
            if num.pull_off_rtol > 0:  # the share of the error estimate's second solve
                single = dataclasses.replace(num, pull_off_rtol=0.0)
                one = min((simulate(scene, single) for _ in range(max(plan.repeat, 1))),
                          key=lambda r: r.wall_s)
                engine[label]["without_estimate"] = {"wall_s": one.wall_s,
                                                     "pull_off": one.pull_off}
            progress(f"vs_numpy {name} engine {label}: {best.wall_s:.3f} s, "
                     f"err {engine[label]['err_pull_off']:.2e}")
        target = min(e["err_pull_off"] for e in engine.values())
        plain = []
        for N, step in plan.plain_ladder:
            pr = plain_unload(scene, N, ref["domain"], step)
            row = {"nodes": N, "step": step, "status": pr.status, "reason": pr.reason,
                   "pull_off": pr.pull_off, "wall_s": pr.wall_s,
                   "influence_s": pr.influence_s, "steps": pr.steps,
                   "factorizations": pr.factorizations,
                   "err_pull_off": relative_error(pr.pull_off, ref["pull_off"])}
            plain.append(row)
            progress(f"vs_numpy {name} plain N={N} step={step}: {pr.status} "
                     f"{pr.wall_s:.2f} s, err {row['err_pull_off']:.2e}")
            if row["err_pull_off"] < target or pr.wall_s > plan.plain_time_limit_s:
                break
        for label, e in engine.items():
            b = _bracket(e["err_pull_off"], plain)
            w, bt = b["equal_or_worse"], b["better"]
            e["plain_equal_or_worse"] = w
            e["plain_better"] = bt
            e["ratio"] = w["wall_s"] / e["wall_s"] if w else None
            e["ratio_better"] = bt["wall_s"] / e["wall_s"] if bt else None
            t_eq = plain_time_at(e["err_pull_off"], plain)
            e["plain_s_interpolated"] = t_eq
            e["ratio_interpolated"] = t_eq / e["wall_s"] if t_eq else None
            if "without_estimate" in e:     # the same pull-off, without the row's error
                e["ratio_without_estimate"] = (w["wall_s"] / e["without_estimate"]["wall_s"]
                                               if w else None)
        out[name] = {"scene": sdict, "reference": {k: ref.get(k) for k in (
                         "pull_off", "source", "uncertainty_pull_off", "domain")},
                     "engine": engine, "plain_ladder": plain}
    return out


def dataset_sample(size: int, seed: int = 0, ranges: dict | None = None,
                   numerics: dict | None = None):
    """A sweep config of ``size`` scenes drawn log-uniformly (seeded, 4 significant digits)
    in ``ranges`` (default :data:`DATASET_RANGES`), model bem, MPL, pull-off only, with
    ``numerics`` (default: the accuracy request ``{pull_off_rtol: 0.01}``)."""
    rng = np.random.default_rng(seed)
    ranges = ranges or DATASET_RANGES
    grid = []
    for _ in range(int(size)):
        d = {name: float(f"{math.exp(rng.uniform(math.log(lo), math.log(hi))):.4g}")
             for name, (lo, hi) in ranges.items()}
        grid.append({**d, "model": "bem"})
    return config_from_dict({"name": f"dataset_sample{size}", "grid": grid,
                             "numerics": dict(numerics or {"pull_off_rtol": 0.01}),
                             "store": {"trajectories": False}})


class _PhaseTimer:
    """Within: the wall time this process spends in each phase of its scenes, exclusive of
    the phases nested in it (seconds and calls per phase, in :attr:`seconds`, :attr:`calls`).

    Phases: ``prony`` (:func:`sweep.engine.problem.prony_series`: a fit, or a read of the
    disk cache), ``influence`` (a mesh's influence matrix, the unit matrix assembled or
    read), ``relaxed_start`` (the elastic relaxed state a scene starts from) and ``unload``
    (the unloading kernel: the solve proper).
    """

    TARGETS = {"prony": ((problem, "prony_series"),),
               "influence": ((mesh, "influence"),),
               "relaxed_start": ((solver, "relaxed_state"), (tip_following, "relaxed_state")),
               "unload": ((solver, "unload"),)}

    def __enter__(self):
        self.seconds = dict.fromkeys(self.TARGETS, 0.0)
        self.calls = dict.fromkeys(self.TARGETS, 0)
        self._stack = []              # the seconds of nested phases, per open phase
        self._saved = []
        for phase, places in self.TARGETS.items():
            for module, name in places:
                orig = getattr(module, name)
                self._saved.append((module, name, orig))
                setattr(module, name, self._timed(phase, orig))
        return self

    def _timed(self, phase, orig):
        def timed(*args, **kwargs):
            self._stack.append(0.0)
            t0 = time.perf_counter()
            try:
                return orig(*args, **kwargs)
            finally:
                spent = time.perf_counter() - t0
                nested = self._stack.pop()
                self.seconds[phase] += spent - nested
                self.calls[phase] += 1
                if self._stack:
                    self._stack[-1] += spent
        return timed

    def __exit__(self, *exc):
        for module, name, orig in self._saved:
            setattr(module, name, orig)


def _campaign_rows(df, rtol: float) -> dict:
    """Counts of a results table: scenes, statuses, failure reasons (their first words) and
    the share of all rows that are ok with ``error_estimate`` <= ``rtol``."""
    ok = df.status == "ok"
    within = ok & (df.error_estimate <= rtol)
    reasons = df.reason[~ok].fillna("").str.split(":").str[0].value_counts()
    return {"scenes": int(len(df)), "ok": int(ok.sum()), "failed": int((~ok).sum()),
            "status_counts": {str(k): int(v) for k, v in df.status.value_counts().items()},
            "failure_reasons": {str(k): int(v) for k, v in reasons.items()},
            "within_tolerance": int(within.sum()),
            "share_within_tolerance": float(within.sum() / max(len(df), 1)),
            "refined_scenes": int((df.refinements > 0).sum()),
            "scene_wall_s_sum": float(df.wall_s.sum())}


def _prony_files() -> int:
    """Prony series in the disk cache (one file per fit)."""
    return len(list(diskcache.cache_dir().glob(f"prony_*{diskcache.RECORD_SUFFIX}")))


def bench_dataset_campaign(plan: BenchPlan) -> dict:
    """A campaign of the external BEM data set's kind (issue 33 item 5), as a user runs it:
    :func:`dataset_sample` of ``plan.dataset_scenes`` scenes through ``run_sweep`` at
    -j{jobs} (fresh workers each time, as ``sweep run`` starts them: forked where the local
    backend forks; ``backend`` says which), at
    ``plan.dataset_numerics`` (the accuracy request).

    ``first``: an empty disk cache (``SWEEP_CACHE_DIR`` a new temporary directory: every
    Prony series fitted, the unit influence matrix assembled); ``warm``: the same directory
    again, a fresh results file. The Numba cache stays warm (compiled kernels are
    ``compile_s``'s figure). ``profile``: every ``dataset_profile_stride``-th scene run again
    in this process from another empty disk cache with :class:`_PhaseTimer`: where a first
    run's time goes (Prony fitting, influence matrices, relaxed starts, the unloading
    solve, and the rest: scheduler, store, meshes, error estimate glue).
    """
    cfg = dataset_sample(plan.dataset_scenes, plan.dataset_seed, plan.dataset_ranges,
                         plan.dataset_numerics)
    rtol = cfg.numerics.pull_off_rtol
    warm_up()
    tmp = Path(tempfile.mkdtemp(prefix="bench-dataset-"))
    walls, rows = {}, {}
    with _fresh_disk_cache():
        fitted = 0
        for label in ("first", "warm"):
            _fresh_workers()
            t = time.perf_counter()
            rep = run_sweep(cfg, jobs=plan.jobs, out=tmp / f"{label}.h5", progress="none",
                            resume=False)
            walls[label] = time.perf_counter() - t
            files = _prony_files()
            backend = rep.backend
            rows[label] = {**_campaign_rows(load(tmp / f"{label}.h5"), rtol), "ran": rep.ran,
                           "prony_series_fitted": files - fitted}
            fitted = files
    picked = [s for _, s in cfg.tasks()[::max(int(plan.dataset_profile_stride), 1)]]
    part = _listed(cfg, picked, f"{cfg.name}_profile")
    with _fresh_disk_cache(), _PhaseTimer() as phases:
        t = time.perf_counter()
        run_sweep(part, jobs=1, out=tmp / "profile.h5", progress="none", resume=False)
        profile_wall = time.perf_counter() - t
        profile_fits = _prony_files()
    shares = {k: v / profile_wall for k, v in phases.seconds.items()}
    shares["other"] = 1.0 - sum(shares.values())
    return {"scenes": len(cfg.tasks()), "seed": plan.dataset_seed,
            "ranges": {k: list(v) for k, v in plan.dataset_ranges.items()},
            "numerics_request": dict(plan.dataset_numerics),
            "numerics": cfg.numerics.to_dict(), "jobs": plan.jobs, "backend": backend,
            "first_s": walls["first"], "warm_s": walls["warm"],
            "first_over_warm": walls["first"] / walls["warm"], "rows": rows,
            "profile": {"scenes": len(picked), "stride": plan.dataset_profile_stride,
                        "wall_s": profile_wall, "prony_series_fitted": profile_fits,
                        "seconds": phases.seconds, "calls": phases.calls, "share": shares},
            "loadavg": os.getloadavg()}


def bench_model_choice(scenes: int = 2000, seed: int = 0) -> dict:
    """Wall time of "auto"'s choice of a model (:func:`sweep.engine.models.model_choice`),
    per scene, over a seeded sample across the declared ranges with the balanced preset
    (every process cache warm: the second pass is timed)."""
    num = Numerics.preset("balanced")
    batch = [Scene(**d, model="auto") for d in sample(scenes, seed, bem_range=False)]
    for sc in batch:
        models.model_choice(sc, num)
    t0 = time.perf_counter()
    chosen = [models.model_choice(sc, num).model for sc in batch]
    wall = time.perf_counter() - t0
    return {"scenes": scenes, "ms_per_scene": 1e3 * wall / scenes,
            "chosen": {m: chosen.count(m) for m in sorted(set(chosen))}}


def bench_all(plan: BenchPlan | None = None, progress=print) -> dict:
    """Every figure of ``results/bench.json`` (issue 9, item 7)."""
    plan = plan or BenchPlan()
    t0 = time.perf_counter()
    report = {"kind": "bench", "machine": {**_machine(), "loadavg_before": os.getloadavg()},
              "plan": dataclasses.asdict(plan)}
    report["compile_s"] = None
    if plan.compile:
        c = compile_seconds()
        report["compile_s"] = {k: v["warm_up_s"] for k, v in c.items()}
        report["compile_detail"] = c
    progress(f"compile_s: {report['compile_s']}")
    warm_up()
    som = bench_step_over_matvec(plan)
    report["step_over_matvec"] = {k: v["ratio"] for k, v in som.items()}
    report["step_over_matvec_detail"] = som
    progress(f"step_over_matvec: {report['step_over_matvec']}")
    ps = bench_prony_speedup(plan)
    report["prony_speedup"] = {k: v["speedup"] for k, v in ps.items()}
    report["prony_speedup_detail"] = ps
    progress(f"prony_speedup: {report['prony_speedup']}")
    camp = bench_campaign(plan)
    report["scenes_per_minute"] = camp[f"scenes_per_minute_j{plan.jobs}"]
    report["parallel_speedup"] = camp["parallel_speedup"]
    report["parallel_speedup_warm_caches"] = camp["parallel_speedup_warm_caches"]
    report["campaign_detail"] = camp
    progress(f"scenes_per_minute: {report['scenes_per_minute']:.1f}, "
             f"parallel_speedup {report['parallel_speedup']:.2f}")
    balanced = bench_balanced_campaign(plan)
    report["campaign_balanced_s"] = balanced["wall_s"]
    report["campaign_balanced_detail"] = balanced
    progress(f"campaign_balanced_s: {balanced['wall_s']:.1f} ({balanced['scenes']} scenes, "
             f"{balanced['status_counts']}, {balanced['tip_following_scenes']} on the "
             f"tip-following mesh)")
    data = bench_dataset_campaign(plan)
    report["dataset_campaign"] = {"first_s": data["first_s"], "warm_s": data["warm_s"],
                                  "scenes": data["scenes"],
                                  "share_within_tolerance":
                                      data["rows"]["first"]["share_within_tolerance"],
                                  "first_run_share": data["profile"]["share"]}
    report["dataset_campaign_detail"] = data
    progress(f"dataset_campaign: {data['scenes']} scenes, first run {data['first_s']:.1f} s, "
             f"warm {data['warm_s']:.1f} s ({data['rows']['first']['status_counts']}, "
             f"{data['rows']['first']['share_within_tolerance']:.3f} within tolerance); "
             f"first run's shares {', '.join(f'{k} {v:.2f}' for k, v in data['profile']['share'].items())}")
    scale = bench_scale(plan)
    report["scale_minutes"] = scale["minutes_estimate"]
    report["scale_detail"] = scale
    progress(f"scale: {scale['scenes']} scenes in about {scale['minutes_estimate']:.1f} min "
             f"(cold upper bound {scale['minutes_sample_rate']:.1f}; sample of "
             f"{scale['sample']}: {scale['status_counts']})")
    report["scene_process_over_import"] = None
    if plan.compile:                                 # fresh processes, as compile_s
        proc = bench_scene_process()
        report["scene_process_over_import"] = proc["ratio"]
        report["scene_process_detail"] = proc
        progress(f"scene_process_over_import: {proc['ratio']:.2f} ({proc['scene_process_s']:.2f} "
                 f"s vs {proc['import_numpy_scipy_s']:.2f} s)")
    choice = bench_model_choice()
    report["model_choice_ms"] = choice["ms_per_scene"]
    report["model_choice_detail"] = choice
    progress(f"model_choice_ms: {choice['ms_per_scene']:.3f} ({choice['chosen']})")
    vs = bench_vs_numpy(plan, progress)
    report["vs_numpy"] = {name: {label: {"engine_s": e["wall_s"], "engine_err": e["err_pull_off"],
                                         "numpy_s": (e["plain_equal_or_worse"] or {}).get("wall_s"),
                                         "numpy_err": (e["plain_equal_or_worse"] or {}).get("err_pull_off"),
                                         "ratio": e["ratio"],
                                         "ratio_interpolated": e["ratio_interpolated"]}
                                 for label, e in d["engine"].items()}
                         for name, d in vs.items()}
    report["vs_numpy_detail"] = vs
    report["machine"]["loadavg_after"] = os.getloadavg()
    report["wall_s"] = time.perf_counter() - t0
    report["definitions"] = {
        "step_over_matvec": "marginal wall per step (full run minus the run cut at 10 steps, "
                            "over the step difference) / median wall of one dense N x N "
                            "mat-vec in Numba; scene PAPER_SCENE, preset matvec_preset at N nodes",
        "prony_speedup": "exact-convolution wall per step / Prony wall per step, same scene, "
                         "same fixed steps (radius control off), key = number of steps",
        "compile_s": "warm_up() seconds in a fresh interpreter: cold = empty NUMBA_CACHE_DIR, "
                     "cached = the same directory afterwards",
        "scenes_per_minute": "the campaign's default numerics on every campaign_stride-th "
                             "scene of its grid, run_sweep with jobs workers (warm), scenes "
                             "per wall minute",
        "campaign_balanced_s": "run_sweep wall of the whole balanced_campaign grid (the v0.1 "
                               "threshold grid at the balanced preset, 480 scenes) at "
                               "-j{jobs}, kernels compiled, fresh workers",
        "parallel_speedup": "run_sweep wall at -j1 / at -j{jobs} (warm workers), same subset, "
                            "both from the on-disk caches filled by a first run "
                            "(campaign_detail.wall_s.first_j1)",
        "parallel_speedup_warm_caches": "the same pair run again in the same processes, "
                                        "every per-process cache (relaxed starts, meshes) "
                                        "warm on both sides: the steady state of a sweep",
        "dataset_campaign": "a campaign of the external BEM data set's kind: "
                            "dataset_scenes scenes drawn log-uniformly (seeded) in "
                            "DATASET_RANGES (a0 1-10 a_ref), model bem, at "
                            "dataset_numerics (pull_off_rtol 0.01: Numerics.for_tolerance), "
                            "run_sweep at -j{jobs} with fresh workers and the Numba cache "
                            "warm; first_s from an empty disk cache, warm_s from the cache "
                            "it filled; share_within_tolerance: rows ok with error_estimate "
                            "<= pull_off_rtol over all rows (first run); first_run_share: "
                            "the shares of a first run's wall (the sample again, in this "
                            "process at -j1, empty disk cache) in the Prony fit, influence "
                            "matrices, relaxed starts, the unloading solve and the rest",
        "scale_minutes": "estimated wall minutes of the whole scale_config grid at -j{jobs}, "
                         "from a seeded random sample of scale_sample scenes: their warm "
                         "(set-up cached) cost scaled to the grid, plus one relaxed start "
                         "per start group and worker, over the sample's parallel speed-up; "
                         "scale_detail.minutes_sample_rate is the cold upper bound",
        "scene_process_over_import": "best-of-3 wall of one `sweep scene` process (the paper "
                                     "scene, fast preset, Numba cache warm) over that of "
                                     "`python -c 'import numpy, scipy'`",
        "model_choice_ms": "milliseconds per scene of model_choice (what model auto runs), "
                           "balanced preset, over a seeded sample of 2000 scenes across the "
                           "declared ranges (a second, warm pass)",
        "vs_numpy": "per scene and engine configuration: engine wall (best of repeat, caches "
                    "warm) and relative pull-off error vs the scene's converged reference; "
                    "the plain numpy solver's most accurate ladder run whose error is still "
                    ">= the engine's (numpy_s, numpy_err); ratio = numpy_s / engine_s, a lower "
                    "bound of the speed-up at equal accuracy; ratio_interpolated = the plain "
                    "time interpolated (log-log) to the engine's error on the plain solver's "
                    "time/error frontier, over engine_s: the estimate at equal accuracy "
                    "(details: vs_numpy_detail)",
    }
    return report


def _git_commit() -> str | None:
    try:
        return subprocess.run(["git", "rev-parse", "HEAD"], cwd=ROOT, capture_output=True,
                              text=True, check=True).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        return None


def _write(report: dict, out: str | None) -> None:
    text = json.dumps(report, indent=2)
    if out:
        p = Path(out)
        p.parent.mkdir(parents=True, exist_ok=True)
        p.write_text(text + "\n")
    click.echo(text)


@click.group()
def bench():
    """Benchmarks of visco-sweep (each writes a JSON report)."""


@bench.command("scheduler")
@click.option("--scenes", type=int, default=40, show_default=True)
@click.option("-j", "--jobs", type=int, default=2, show_default=True)
@click.option("--repeat", type=int, default=3, show_default=True,
              help="Repetitions (the minimum wall of each measurement is used).")
@click.option("--cli/--no-cli", default=True, show_default=True,
              help="Also time `sweep run -j1/-jN` subprocesses.")
@click.option("--out", default=None, help="JSON report path.")
def scheduler_cmd(scenes, jobs, repeat, cli, out):
    """Parallel efficiency and per-scene overhead on the scaled-up smoke grid."""
    _write(bench_scheduler(scenes=scenes, jobs=jobs, repeat=repeat, cli=cli), out)


@bench.command("store")
@click.option("--rows", type=int, default=1000, show_default=True)
@click.option("--trajectories/--no-trajectories", default=False, show_default=True)
@click.option("--out", default=None, help="JSON report path.")
def store_cmd(rows, trajectories, out):
    """Throughput of the crash-safe results store."""
    _write(bench_store(rows=rows, trajectories=trajectories), out)


@bench.command("scene")
@click.option("--repeat", type=int, default=3, show_default=True)
@click.option("--compile/--no-compile", "compile_", default=True, show_default=True)
@click.option("--out", default=None, help="JSON report path.")
def scene_cmd(repeat, compile_, out):
    """Solver speed: presets, step/matvec ratio, Prony vs exact, compile time."""
    _write(bench_scene(repeat=repeat, compile_=compile_), out)


@bench.command("convergence")
@click.option("--mu", type=float, default=6.0, show_default=True)
@click.option("--nodes", default="1000,1500,2000", show_default=True)
@click.option("--out", default=None, help="JSON report path.")
def convergence_cmd(mu, nodes, out):
    """Mesh convergence of the elastic pull-off (spacing domain/(N-1), domain 5)."""
    _write(bench_convergence(mu=mu, nodes=tuple(int(x) for x in nodes.split(","))), out)


#: the plain solver's ladder towards the accurate preset's errors (a few 1e-6 on two bench
#: scenes): runs of 4-110 s each on this machine
ACCURATE_PLAIN_LADDER = ((600, 0.05), (900, 0.05), (900, 0.025), (1200, 0.025), (1600, 0.025),
                         (2000, 0.025))
#: a check of the stored references at the accurate preset's errors: the same scene on the
#: graded mesh at 108 spacings per tip zone, step 0.025 h0 (a discretization unlike the
#: references' uniform 2000 nodes)
REFERENCE_CHECK = dict(band_resolution=108.0, step=0.025, da_max=0.1, prony_rtol=1e-8,
                       tol=1e-11, pull_off_rtol=0.0, max_nodes=5000, time_budget_s=900.0)


def bench_vs_numpy_accurate(repeat: int = 3, progress=print) -> dict:
    """:func:`bench_vs_numpy` at the accurate preset: the speed-up at equal accuracy where
    the errors are a few 1e-6 (the plain solver's ladder :data:`ACCURATE_PLAIN_LADDER`, up
    to 150 s a run), and each stored reference checked against a second discretization
    (:data:`REFERENCE_CHECK`): where the two differ by as much as the engine's error, the
    ratio there cannot be read."""
    plan = BenchPlan(engine_numerics={"balanced": {"preset": "balanced"},
                                      "accurate": {"preset": "accurate"}},
                     plain_ladder=ACCURATE_PLAIN_LADDER, plain_time_limit_s=150.0,
                     repeat=repeat)
    out = bench_vs_numpy(plan, progress=progress)
    refs = load_references()
    for name, sdict in plan.vs_numpy_scenes.items():
        check = simulate(Scene(**sdict), Numerics.preset("accurate", **REFERENCE_CHECK))
        ref = refs[name]["pull_off"]
        out[name]["reference_check"] = {
            "numerics": REFERENCE_CHECK, "status": check.status, "pull_off": check.pull_off,
            "wall_s": check.wall_s, "relative_difference": relative_error(check.pull_off, ref)}
        progress(f"vs_numpy_accurate {name}: reference check {check.pull_off:.9g} "
                 f"({relative_error(check.pull_off, ref):.2e} from the stored reference)")
    return {"kind": "vs_numpy_accurate", "machine": _machine(), "scenes": out}


@bench.command("vs-numpy-accurate")
@click.option("--repeat", type=int, default=3, show_default=True)
@click.option("--out", default="results/bench/vs_numpy_accurate.json", show_default=True,
              help="JSON report path.")
def vs_numpy_accurate_cmd(repeat, out):
    """The engine against the plain numpy solver at the accurate preset (about 10 min)."""
    _write(bench_vs_numpy_accurate(repeat=repeat, progress=lambda m: click.echo(m, err=True)),
           out)


@bench.command("all")
@click.option("--tiny", is_flag=True, help="Seconds-long configuration (harness check).")
@click.option("--out", default="results/bench.json", show_default=True, help="JSON report path.")
def all_cmd(tiny, out):
    """Every figure of issue 9: step/matvec, Prony speed-up, compile, campaign, vs numpy."""
    report = bench_all(BenchPlan.tiny() if tiny else BenchPlan(),
                       progress=lambda m: click.echo(m, err=True))
    _write(report, out)


@bench.command("dataset")
@click.option("--scenes", type=click.IntRange(1), default=BenchPlan.dataset_scenes,
              show_default=True, help="Scenes in the seeded sample.")
@click.option("--seed", type=int, default=BenchPlan.dataset_seed, show_default=True)
@click.option("--pull-off-rtol", type=click.FloatRange(0.0, 1.0, min_open=True), default=0.01,
              show_default=True, help="The accuracy asked for (numerics: {pull_off_rtol: ...}).")
@click.option("-j", "--jobs", type=click.IntRange(1), default=2, show_default=True)
@click.option("--out", default=None, help="JSON report path.")
def dataset_cmd(scenes, seed, pull_off_rtol, jobs, out):
    """A campaign of the external BEM data set's kind: first run and warm cache."""
    _write(bench_dataset_campaign(BenchPlan(dataset_scenes=scenes, dataset_seed=seed, jobs=jobs,
                                            dataset_numerics={"pull_off_rtol": pull_off_rtol})),
           out)


@bench.command("scale")
@click.option("--sample", type=int, default=80, show_default=True,
              help="Scenes in the random sample.")
@click.option("-j", "--jobs", type=int, default=2, show_default=True)
@click.option("--config", "config", default="configs/scale.yaml", show_default=True)
@click.option("--out", default=None, help="JSON report path.")
def scale_cmd(sample, jobs, config, out):
    """Estimated minutes for the 10,640-scene grid over the paper's ranges (a random sample)."""
    warm_up()
    _write(bench_scale(BenchPlan(scale_config=config, scale_sample=sample, jobs=jobs)), out)


@bench.command("reference")
@click.option("--only", default=None, help="Comma-separated scene names (default: all).")
@click.option("--out", default=str(REFERENCES), show_default=True)
def reference_cmd(only, out):
    """Converged references of the tradeoff and vs-numpy scenes (slow: minutes per scene)."""
    path = Path(out)
    data = json.loads(path.read_text()) if path.exists() else {"scenes": {}}
    scenes = {**TRADEOFF_SCENES, **VS_NUMPY_SCENES}
    names = only.split(",") if only else list(scenes)
    for name in names:
        if name not in scenes:
            raise click.BadParameter(f"unknown scene {name!r} (allowed: {', '.join(scenes)})",
                                     param_hint="--only")
    for name in names:
        ref = compute_reference(scenes[name])
        ref["engine_commit"] = _git_commit()
        data["scenes"][name] = ref
        data["definition"] = ("pull_off, crack_speed: the engine with the accurate preset and "
                              f"{REFERENCE_OVERRIDES}; uncertainty_*: relative difference to "
                              "the accurate preset")
        path.write_text(json.dumps(data, indent=2) + "\n")
        click.echo(f"{name}: pull-off {ref['pull_off']:.8g} (+-{ref['uncertainty_pull_off']:.1e}),"
                   f" crack speed {ref['crack_speed']:.6g}, {ref['wall_s']:.0f} s", err=True)


@bench.command("tradeoff")
@click.option("--quick", is_flag=True, help="A few points on two scenes (smoke test).")
@click.option("--out", default="results/tradeoff", show_default=True, help="Output directory.")
@click.option("--repeat", default=2, show_default=True, type=click.IntRange(1, 10),
              help="Rounds over each scene's grid (every numerics once a round), the "
                   "best wall kept: the first round pays each numerics' set-up (Prony fit, "
                   "relaxed start on its mesh) that a campaign pays once per worker.")
@click.option("--from-table", is_flag=True,
              help="Derive presets.json again from OUT/table.csv, running nothing.")
def tradeoff_cmd(quick, out, repeat, from_table):
    """Accuracy vs wall time over a grid of numerics: table.csv, pareto.png, presets.json."""
    if from_table:
        click.echo(json.dumps(rederive_presets(out), indent=2, default=str))
        return
    report = write_tradeoff(out, quick=quick, repeat=repeat,
                            progress=lambda m: click.echo(m, err=True))
    click.echo(json.dumps(report["presets"], indent=2, default=str))


@bench.command("compare")
@click.argument("before", type=click.Path(exists=True, dir_okay=False))
@click.argument("after", type=click.Path(exists=True, dir_okay=False))
def compare_cmd(before, after):
    """Agreement of two results files of the same scenes (e.g. two engine versions)."""
    _write(compare_results(before, after), None)


@bench.command("newton-diagnosis")
@click.option("--n", type=float, default=0.2, show_default=True)
@click.option("--k", type=float, default=0.5, show_default=True)
@click.option("--mu", type=float, default=3.24, show_default=True)
@click.option("--rate", type=float, default=0.1, show_default=True)
@click.option("--delta0", type=float, default=43.1661, show_default=True)
@click.option("--preset", default="fast", show_default=True)
@click.option("--max-nodes", type=int, default=1000, show_default=True)
@click.option("--at-step", type=int, default=300, show_default=True)
@click.option("--out", default=None, help="JSON report path.")
def newton_diagnosis_cmd(n, k, mu, rate, delta0, preset, max_nodes, at_step, out):
    """Newton's cost on one scene: counters, the chord map's contraction and the predictor's
    error at the crack tip (default: the scale campaign's costliest kind of scene)."""
    _write(newton_diagnosis(Scene(n=n, k=k, mu=mu, rate=rate, delta0=delta0),
                            Numerics.preset(preset, max_nodes=max_nodes), at_step), out)


@bench.command("presets")
@click.option("--repeat", type=int, default=1, show_default=True)
@click.option("--out", default=None, help="JSON report path.")
def presets_cmd(repeat, out):
    """Speed/accuracy of the presets against the independent reference values."""
    _write(bench_presets(repeat=repeat), out)


if __name__ == "__main__":  # pragma: no cover
    bench()
