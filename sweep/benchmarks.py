"""Benchmarks, one subcommand per kind, each writing a JSON report::

    python -m sweep.benchmarks scheduler --out results/bench/scheduler.json

``scheduler``: parallel efficiency and per-scene overhead of the sweep engine. The grid is
``configs/smoke.yaml`` scaled up to ``--scenes`` scenes (its two n values times a finer
log-spaced rate axis over the same range). In one process, on one machine:

1. ``bare``: ``sweep.solver.simulate`` called in a plain loop (after ``warm_up``);
2. ``j1``: ``run_sweep(jobs=1)`` (scheduler + store, in-process);
3. ``j2``: ``run_sweep(jobs=2)`` with fresh loky workers (includes spawning them and their
   Numba cache load), then ``j2_warm`` with the reused workers;
4. optionally (``--cli``) the same with ``sweep run -j1`` / ``-j2`` subprocesses
   (each includes interpreter start-up, imports and the Numba cache load).

Reported: parallel efficiency ``t_j1 / (2 t_j2)`` and per-scene overhead
``(t_j1 - sum of bare simulate walls) / scenes``. ``store``: the cost of appending
``--rows`` rows and consolidating them (throughput of the results store).
"""
from __future__ import annotations

import json
import os
import platform
import subprocess
import sys
import tempfile
import time
from datetime import datetime, timezone
from pathlib import Path

import click
import numpy as np

ROOT = Path(__file__).resolve().parents[1]


def _machine() -> dict:
    return {"cpus": os.cpu_count(), "platform": platform.platform(),
            "python": platform.python_version(),
            "date": datetime.now(timezone.utc).isoformat(timespec="seconds")}


def scaled_smoke(scenes: int = 40, base: str | Path | None = None):
    """configs/smoke.yaml with its rate axis refined so the grid has about ``scenes`` scenes."""
    from .config import load_config, scale_grid

    cfg = load_config(base or ROOT / "configs" / "smoke.yaml")
    g = cfg.grids[0]
    per_rate = max(1, len(cfg.tasks()) // len(g["rate"]))
    n_rates = max(2, round(scenes / per_rate))
    lo, hi = np.log10(min(g["rate"])), np.log10(max(g["rate"]))
    rates = [float(r) for r in np.logspace(lo, hi, n_rates)]
    return scale_grid(cfg, "rate", rates)


def _fresh_loky_workers() -> None:
    """Shut the reusable loky executor down, so the next sweep spawns new workers."""
    try:
        from joblib.externals.loky import get_reusable_executor

        get_reusable_executor().shutdown(wait=True)
    except Exception:  # pragma: no cover
        pass


def bench_scheduler(scenes: int = 40, jobs: int = 2, repeat: int = 3, cli: bool = False,
                    workdir: str | Path | None = None) -> dict:
    """Measure parallel efficiency and scheduler+store overhead per scene (see module doc).

    Each measurement is repeated ``repeat`` times, interleaved, and the minimum wall is
    used (robust to other load on the machine; the load averages are reported too).
    ``j{jobs}`` always starts fresh worker processes, like a new ``sweep run`` does;
    ``j{jobs}_warm`` reuses the workers of the previous call.
    """
    from . import solver
    from .scheduler import run_sweep
    from .store import load

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
            _fresh_loky_workers()
        t, c = time.perf_counter(), time.process_time()
        rep = run_sweep(cfg, jobs=j, out=tmp / f"{name}.h5", progress="none", resume=False)
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
                                   f"in one process; every j{jobs} run spawns fresh loky "
                                   f"workers (their start-up and Numba cache load included)",
            "overhead_per_scene_s": "(min t(j1) - min sum of bare simulate walls) / scenes",
            "overhead_cpu_per_scene_s": "the same with CPU time of the process",
            "task_cpu_over_wall": "CPU/wall of the scenes in the workers: < 1 means the "
                                  "cores were shared with other load",
        },
    }
    if cli:
        import yaml

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
    from .store import ResultStore

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
        from . import solver
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
    from numba import njit

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
    from .solver import simulate
    best = None
    for _ in range(repeat):
        with _KernelTimer() as kt:
            res = simulate(scene, numerics)
        row = {"wall_s": res.wall_s, "kernel_s": kt.seconds, "status": res.status,
               "pull_off": res.pull_off, "crack_speed": res.crack_speed, "steps": res.steps,
               "newton_iterations": res.newton_iterations,
               "factorizations": res.factorizations, "prony_terms": res.prony_terms,
               "nodes": numerics.nodes, "spacing": res.spacing}
        if best is None or row["wall_s"] < best["wall_s"]:
            best = row
    return best


def compile_seconds() -> dict:
    """Numba compile time: ``warm_up()`` in a fresh interpreter with an empty cache
    directory (cold), then again with the cache it left (cached)."""
    code = ("import time; t=time.perf_counter(); from sweep.solver import warm_up; "
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


def bench_scene(repeat: int = 3, compile_: bool = True) -> dict:
    """Issue-3 numbers: per-preset wall time of the paper's scene, time per step over one
    dense matvec, Prony vs exact speed-up at equal steps, compile time."""
    from .scene import PRESETS, Numerics, Scene
    from .solver import warm_up
    warm_up()
    scene = Scene(**PAPER_SCENE)
    report = {"kind": "scene", "machine": _machine(), "scene": PAPER_SCENE, "presets": {},
              "presets_at_500_nodes": {}}
    for name in PRESETS:
        for key, num in (("presets", Numerics.preset(name)),
                         ("presets_at_500_nodes", Numerics.preset(name, nodes=500))):
            row = _scene_run(scene, num, repeat)
            tmv = matvec_seconds(num.nodes)
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
    (shared/reference/independent_solutions.yaml) and cost, per case and preset."""
    import yaml
    from .scene import PRESETS, Numerics, Scene
    from .solver import warm_up
    warm_up()
    ref = yaml.safe_load(REFERENCE_YAML.read_text())
    rows = []
    for case in ref["viscoelastic"]:
        scene = Scene(**case["scene"])
        for name in PRESETS:
            r = _scene_run(scene, Numerics.preset(name), repeat)
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
    import yaml
    from .scene import Numerics, Scene
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


@bench.command("presets")
@click.option("--repeat", type=int, default=1, show_default=True)
@click.option("--out", default=None, help="JSON report path.")
def presets_cmd(repeat, out):
    """Speed/accuracy of the presets against the independent reference values."""
    _write(bench_presets(repeat=repeat), out)


if __name__ == "__main__":  # pragma: no cover
    bench()
