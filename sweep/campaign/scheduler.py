"""Run a sweep: spread the scenes of a config over the cores (or a dask cluster), store results.

:func:`run_sweep` is the Python entry point behind ``sweep run``::

    from sweep import run_sweep
    report = run_sweep("configs/smoke.yaml", jobs=2)          # processes on this machine
    report = run_sweep(cfg, backend="dask", scheduler="tcp://head:8786")   # a cluster

Scheduling. joblib ``Parallel(return_as="generator_unordered", batch_size=1)`` (forked
workers: a ``concurrent.futures`` process pool, the same tasks in the same order) runs one
chunk of scenes per task (:func:`dispatch_chunks`): the scenes of a chunk share their
relaxed start, so one worker solves it once; chunks are small (a quarter of a worker's share
of the estimated cost at most) and dispatched the most expensive first
(longest-processing-time first, so that no large chunk starts last and leaves one core idle
at the end of the grid). Results stream back to the parent as each chunk finishes and the
parent, the single writer, appends them to the crash-safe store (:mod:`sweep.campaign.store`).
Backends:

* ``local`` (default): ``jobs`` worker processes on this machine (default: all cores), each
  with one BLAS/OpenMP/Numba thread. On Linux, in a process that runs no other thread, they
  are forked from the parent once it has loaded the kernels (:mod:`sweep.campaign.forked`:
  they start in milliseconds, where a new interpreter takes about a second); elsewhere they
  are loky's. ``jobs=1`` runs in the parent process. The report's ``backend`` says which ran
  (``fork`` or ``loky``).
* ``loky``: always joblib/loky worker processes (new interpreters,
  ``inner_max_num_threads=1``).
* ``dask``: the same tasks through joblib's dask backend on a ``dask.distributed`` cluster at
  ``scheduler`` (``tcp://host:8786``); without an address a ``LocalCluster`` with ``jobs``
  single-threaded worker processes is started for the run.

A cold Numba cache is warmed in the parent (``sweep.engine.bem.warm_up()``, which compiles and
writes the on-disk cache) before the grid starts; every loky or dask worker process warms it
on its first task (a cache load), forked workers get it from the parent, which loads it
before forking them, and a sequential run (``-j 1``) loads it in the parent. Resume: scenes whose id is already in the results file (or
its journal) are skipped, so running the same command again completes an interrupted sweep.
"""
from __future__ import annotations

import math
import os
import re
import socket
import sys
import tempfile
import time
import traceback
import warnings
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable

import click
import numpy as np
from joblib import Parallel, delayed, parallel_config
from tqdm import tqdm

from .config import SweepConfig, as_config
from ..errors import InputError, check_int, check_range
from ..scene import ENGINE_REVISION, Result
from . import spool
from .store import (ResultStore, StoreBusyError, error_log_path, older_revision_rows,
                    plain_row, real_path, revision_counts)
from ..threads import THREAD_VARS, exit_with_parent, limit_env, limit_loaded_pools
from .forked import ForkedWorkers, usable as forked_workers_usable

BACKENDS = ("local", "loky", "dask")
PROGRESS_MODES = ("auto", "bar", "log", "none")


class SweepRuntimeError(RuntimeError):
    """A sweep could not run or was stopped (cluster unreachable, worker crash, ...).

    The CLI maps it to exit code 1. Results finished before the error are on disk.
    """


class SweepInterrupted(KeyboardInterrupt):
    """A sweep stopped by SIGINT (Ctrl-C): ``kept`` finished scenes of ``total`` are saved in
    ``output``; running the same command again resumes. A KeyboardInterrupt, so code that
    catches those still does."""

    def __init__(self, kept: int, total: int, output: Path):
        super().__init__(f"interrupted: {kept} of {total} scenes are kept in {output}")
        self.kept, self.total, self.output = kept, total, output


@dataclass
class SweepReport:
    """What :func:`run_sweep` did."""

    output: Path
    name: str
    total: int
    skipped: int
    ran: int
    failed: int
    wall_s: float
    backend: str
    jobs: int
    backup: Path | None = None
    failed_ids: list = field(default_factory=list)
    #: scenes that hit an internal error (status "error": a bug, not a result), not in failed
    errors: int = 0
    error_ids: list = field(default_factory=list)
    error_log: Path | None = None

    def line(self) -> str:
        text = (f"{self.name}: {self.total} scenes ({self.ran} ran, {self.skipped} already "
                f"done, {self.failed} failed) in {self.wall_s:.1f} s -> {self.output}")
        if self.backup is not None:
            text += f" (previous results moved to {self.backup})"
        return text

    def error_line(self) -> str:
        """The end-of-sweep line about internal errors ("" when there were none)."""
        if not self.errors:
            return ""
        return (f"{self.errors} scene{'s' if self.errors > 1 else ''} hit an internal error "
                f"(a bug, not a result; status \"error\"), see {self.error_log}")


# ----------------------------------------------------------------------------- workers
_WORKER_READY = False
#: True once this process ran the kernels' warm-up (a forked worker inherits it: its
#: parent loaded them before the fork)
_KERNELS_LOADED = False


def _prepare_worker(warm: bool, limit_threads: bool = True) -> None:
    """Once per process: end with the parent (:func:`exit_with_parent`), one thread for
    BLAS/OpenMP/Numba, then warm the Numba cache (unless the parent loaded it before forking
    this worker)."""
    global _WORKER_READY
    if _WORKER_READY:
        return
    exit_with_parent()
    if limit_threads:
        limit_env(THREAD_VARS)
        limit_loaded_pools()
        if "numba" in sys.modules:      # a forked worker: numba read them in the parent
            sys.modules["numba"].config.reload_config()
    if warm and not _KERNELS_LOADED:
        # the engine (numba) is imported here, after the thread limits above: numba reads
        # NUMBA_NUM_THREADS when it loads (the same in run_scene and _warm_parent)
        from ..engine import bem as solver

        solver.warm_up()
    _WORKER_READY = True


def _one_line(text: str, limit: int = 300) -> str:
    text = " ".join(str(text).split())
    return text if len(text) <= limit else text[: limit - 3] + "..."


def run_scene(scene, numerics, trajectories: bool = False, simulate: Callable | None = None,
              in_worker: bool = True, warm: bool = True):
    """Worker task: simulate one scene; return ``(row, trajectory or None)``, plain data.

    Never raises for a failing scene. The engine reports numerical failures as
    ``status="failed"`` with a reason; an exception that escapes it is a bug (TypeError, ...)
    and becomes ``status="error"`` with the exception as reason and its traceback in the row's
    :data:`TRACEBACK_KEY` (the parent writes it to the error log and drops it from the row).
    ``in_worker=False`` (the sequential path in the parent) leaves the thread limits alone;
    ``warm=False`` (a grid whose models need no BEM kernel, on a cold Numba cache) leaves them
    uncompiled.
    """
    if in_worker:
        _prepare_worker(warm=warm and simulate is None)
    if simulate is None:   # after _prepare_worker: see there
        from ..engine.models import simulate   # the front door: dispatches on scene.model
    t0 = time.perf_counter()
    c0 = time.process_time()
    tb = None
    try:
        res = simulate(scene, numerics)
    except Exception as exc:  # a bug in one scene must not stop the sweep, nor pass for a result
        tb = traceback.format_exc()
        res = Result(scene=scene, numerics=numerics, status="error",
                     reason=_one_line(f"internal error {type(exc).__name__}: {exc}"))
        res.model_used = getattr(scene, "model", "")
    task_wall = time.perf_counter() - t0
    task_cpu = time.process_time() - c0
    row = res.to_row()
    row["reason"] = _one_line(row.get("reason", "") or "")
    wall = row.get("wall_s")
    if wall is None or not math.isfinite(float(wall)) or float(wall) <= 0.0:
        row["wall_s"] = task_wall
    row["task_wall_s"] = task_wall
    row["task_cpu_s"] = task_cpu
    row["worker"] = f"{socket.gethostname()}:{os.getpid()}"
    row["finished_at"] = time.time()
    row["engine_revision"] = ENGINE_REVISION
    traj = None
    if trajectories and res.trajectory:
        traj = {str(k): np.asarray(v, dtype=np.float64) for k, v in res.trajectory.items()}
    row = plain_row(row)
    if tb is not None:
        row[TRACEBACK_KEY] = tb
    return row, traj


#: key of the traceback an internal error adds to a worker's row (never stored in the table)
TRACEBACK_KEY = "_traceback"


def log_internal_error(log: Path, row: dict, tb: str) -> None:
    """Append one internal error (time, scene id, model, scene, traceback) to ``log``."""
    scene = {k: row.get(k) for k in ("n", "k", "mu", "a0", "delta0", "rate", "material",
                                     "model", "stop") if k in row}
    text = (f"=== {time.strftime('%Y-%m-%dT%H:%M:%SZ', time.gmtime())} scene {row['scene_id']} "
            f"model {row.get('model_used') or row.get('model', '')}\n"
            f"scene: {scene}\n{tb.rstrip()}\n\n")
    with open(log, "a", encoding="utf-8") as fh:
        fh.write(text)


def template_row(config: SweepConfig) -> dict:
    """A row with every column of the runs table (used for an empty table's schema)."""
    _, scene = config.tasks()[0]
    row = Result(scene=scene, numerics=config.numerics).to_row()
    row.update(task_wall_s=0.0, task_cpu_s=0.0, worker="", finished_at=0.0,
               engine_revision=ENGINE_REVISION)
    return row


# ----------------------------------------------------------------------------- progress
def _num(x) -> str | None:
    if x is None or isinstance(x, bool):
        return None
    try:
        x = float(x)
    except (TypeError, ValueError):
        return None
    return None if math.isnan(x) else f"{x:.4g}"


def scene_inputs(row: dict) -> str:
    """The inputs of a scene as ``n=0.8 k=0.5 mu=3.24 a0=2 rate=100`` (``delta0=`` for a
    scene started from an indentation; a test protocol's, a process zone's and a compliant
    machine's fields where the scene has them; ``material=``, ``model=``, ``stop=``,
    ``dwell_hold=`` when not the default), so that the scenes of a grid over any axis are
    told apart."""
    parts = []
    for name in ("n", "k", "mu", "a0", "delta0", "rate", "approach_rate", "preload", "dwell",
                 "pz_v0", "pz_xi", "machine_stiffness"):
        v = _num(row.get(name))
        if v is not None:
            parts.append(f"{name}={v}")
    defaults = {"pz_law": "none", "material": "mpl", "model": "bem", "stop": "pulloff"}
    if _num(row.get("dwell")) is not None:       # what a dwell holds: a protocol's only
        defaults = {"dwell_hold": "force", **defaults}
    for name, default in defaults.items():
        v = row.get(name)
        if v not in (None, "", default):
            parts.append(f"{name}={v}")
    return " ".join(parts)


class _Bar(tqdm):
    """A tqdm bar without tqdm's monitor thread (which outlives the bar by up to 10 s, and a
    process running a second thread forks no workers: :mod:`sweep.campaign.forked`)."""

    monitor_interval = 0


class Progress:
    """Progress display: a tqdm bar on a terminal ("bar"), one line per scene ("log").

    "log" is the mode for files and CI logs (no carriage returns): each finished scene prints
    ``[done/total] <scene_id> <status> n=... k=... mu=... a0=... rate=... pull_off=...
    wall=...s`` (the scene's inputs, :func:`scene_inputs`; and the reason of a failure).
    A callable ``mode`` gets a dict (done, total, failed, eta, row) after each scene instead.
    """

    def __init__(self, mode, total: int, already: int, stream=None):
        self.stream = stream if stream is not None else sys.stderr
        if callable(mode):
            self.callback, mode = mode, "none"
        else:
            self.callback = None
        if mode == "auto":
            isatty = getattr(self.stream, "isatty", lambda: False)
            mode = "bar" if isatty() else "log"
        self.mode = mode
        self.total, self.done, self.already = total, already, already
        self.failed = 0
        self.t0 = time.monotonic()
        self.width = len(str(total))
        self.bar = None

    def _echo(self, text: str) -> None:
        if self.bar is not None:
            self.bar.write(text, file=self.stream)
            return
        click.echo(text, file=self.stream)
        with_flush = getattr(self.stream, "flush", None)
        if with_flush:
            with_flush()

    def eta(self) -> float:
        """Seconds left, from the mean time per scene run so far (inf before the first)."""
        ran = self.done - self.already
        if ran <= 0:
            return math.inf
        return (time.monotonic() - self.t0) / ran * (self.total - self.done)

    def message(self, text: str) -> None:
        if self.mode != "none":
            self._echo(text)

    def start(self) -> None:
        if self.mode == "bar":
            self.bar = _Bar(total=self.total, initial=self.already, file=self.stream,
                            unit="scene", dynamic_ncols=True, postfix="0 failed")

    def update(self, row: dict) -> None:
        self.done += 1
        if row.get("status") != "ok":
            self.failed += 1
        if self.callback is not None:
            self.callback({"done": self.done, "total": self.total, "failed": self.failed,
                           "eta": self.eta(), "row": row})
        if self.bar is not None:
            self.bar.set_postfix_str(f"{self.failed} failed", refresh=False)
            self.bar.update(1)
        elif self.mode == "log":
            po = row.get("pull_off")
            po = f"{po:.5g}" if isinstance(po, float) else str(po)
            inputs = scene_inputs(row)
            text = (f"[{self.done:{self.width}d}/{self.total}] {row['scene_id']} "
                    f"{row.get('status')} {inputs + ' ' if inputs else ''}pull_off={po} "
                    f"wall={row.get('wall_s', 0.0):.3g}s")
            if row.get("status") != "ok" and row.get("reason"):
                text += f" reason: {row['reason']}"
            self._echo(text)

    def close(self) -> None:
        if self.bar is not None:
            self.bar.close()
            self.bar = None


# ----------------------------------------------------------------------------- helpers
def estimated_cost(scene, numerics) -> float:
    """A relative cost estimate of one scene, used only to order the dispatch.

    The hereditary BEM's cost grows with the number of nodes over the crack band and the
    number of steps across it, both about proportional to the initial contact radius in
    units of the tip zone, and with the slowness of the unloading (at slow rates the
    contact relaxes as it opens and the tip travels further). Measured on the threshold
    campaign (mu = 3.24): mean wall 0.03-0.1 s at a0 = 1-2, 0.9 s at a0 = 6, 1.6 s at
    a0 = 8; rate 1 costs about 3x rate 1e6. The estimate needs only arithmetic on the
    scene (no mesh is built); a scene it cannot size gets cost 1.
    """
    try:
        # lazy: engine.problem loads numba, which a worker loads only after _prepare_worker
        from ..engine.problem import initial_estimates, tip_zone

        _, a_est, _ = initial_estimates(scene, numerics)
        size = max(a_est, 0.0) / tip_zone(scene.mu)
        slow = 1.0 + 2.0 / (1.0 + max(math.log10(scene.rate), 0.0))   # rate > 0 (Scene)
        cost = (1.0 + size) ** 2 * slow
        return cost if math.isfinite(cost) else 1.0
    except Exception:  # ordering is a heuristic: never let it stop a sweep
        return 1.0


def dispatch_order(todo: list, numerics, costs: dict | None = None) -> list:
    """``todo`` [(scene_id, scene), ...] sorted by :func:`estimated_cost`, largest first
    (stable: equal costs keep the config's order; ``costs`` {scene_id: cost} when already
    estimated). The results file does not depend on the order: rows are stored as scenes
    finish, keyed by scene id."""
    if costs is None:
        costs = {sid: estimated_cost(scene, numerics) for sid, scene in todo}
    order = sorted(range(len(todo)), key=lambda i: -costs[todo[i][0]])
    return [todo[i] for i in order]


#: a dispatch chunk holds at most this fraction of the grid's estimated cost per worker
#: (1/4: at most a quarter of a worker's share, so the largest chunks still balance) ...
CHUNK_COST_FRACTION = 0.25
#: ... and at most this many scenes (a dask worker's rows come per chunk: its progress, and
#: what its crash loses; a local worker's rows come per scene, sweep.campaign.spool)
CHUNK_SCENES = 24


def start_group(scene) -> tuple:
    """Scenes that share a relaxed start (the per-process cache of :mod:`sweep.engine.initial`):
    same material ratio k, Tabor parameter and initial state; n and the rate do not enter."""
    return tuple(getattr(scene, name, None) for name in ("model", "k", "mu", "a0", "delta0"))


def dispatch_chunks(todo: list, numerics, n_jobs: int) -> list:
    """``todo`` [(scene_id, scene), ...] cut into dispatch chunks, largest first.

    Each chunk holds scenes of one start group (:func:`start_group`), so that the worker
    that runs it solves the group's relaxed start once rather than every worker once per
    group (on the threshold campaign that duplication cost about 10 % of the -j2 wall).
    A group is cut, in :func:`dispatch_order`, into chunks of at most CHUNK_SCENES scenes
    and CHUNK_COST_FRACTION of a worker's share of the estimated cost; the chunks are
    dispatched longest-processing-time first. Returns a list of lists of (scene_id, scene)
    that together are a permutation of ``todo``.
    """
    if not todo:
        return []
    costs = {sid: estimated_cost(scene, numerics) for sid, scene in todo}
    cap = CHUNK_COST_FRACTION * sum(costs.values()) / max(n_jobs, 1)
    groups: dict = {}
    for sid, scene in dispatch_order(todo, numerics, costs):
        groups.setdefault(start_group(scene), []).append((sid, scene))
    chunks = []
    for members in groups.values():
        chunk, cost = [], 0.0
        for item in members:
            c = costs[item[0]]
            if chunk and (len(chunk) >= CHUNK_SCENES or cost + c > cap):
                chunks.append((cost, chunk))
                chunk, cost = [], 0.0
            chunk.append(item)
            cost += c
        chunks.append((cost, chunk))
    order = sorted(range(len(chunks)), key=lambda i: -chunks[i][0])
    return [chunks[i][1] for i in order]


def check_output_writable(path: Path) -> None:
    """Raise InputError unless a results file can be created at ``path``."""
    if path.is_dir():
        raise InputError(f"output {path} is a directory; give a file path such as "
                         f"{path / 'results.h5'}")
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise InputError(f"output {path}: cannot create directory {path.parent} "
                         f"({exc.strerror or exc})") from None
    try:
        fd, name = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.probe-")
        os.close(fd)
        os.unlink(name)
    except OSError as exc:
        raise InputError(f"output {path}: cannot write in {path.parent} "
                         f"({exc.strerror or exc})") from None
    if path.exists() and not os.access(path, os.R_OK):
        raise InputError(f"output {path} exists but cannot be read")


def _first_line(exc: BaseException) -> str:
    text = str(exc).strip().splitlines()
    return text[0] if text else type(exc).__name__


#: a dask scheduler's address: [protocol://]host:port (host a name, an IPv4 or a bracketed
#: IPv6 address), or an in-process one
_ADDRESS = re.compile(r"^(?:[a-z][a-z0-9+.-]*://)?(?:\[[0-9a-fA-F:.]+\]|[^\s/:\[\]]+):\d{1,5}$")


def check_scheduler_address(address: str) -> str:
    """``address`` if it is a dask scheduler's address (``tcp://host:8786``, ``host:8786``,
    ``inproc://...``), else InputError naming it: a malformed one had waited out the
    connection timeout, then dask's client cleanup 20 s more, with a traceback."""
    text = str(address).strip()
    if text.startswith("inproc://") or _ADDRESS.match(text):
        return text
    raise InputError(f"scheduler must be an address such as tcp://host:8786, host and port "
                     f"(got {address!r})")


def _connect_dask(scheduler, jobs, timeout):
    try:  # optional dependency (visco-sweep[cluster])
        from dask.distributed import Client, LocalCluster
    except ImportError:
        raise SweepRuntimeError("backend dask needs dask.distributed: pip install "
                                "'visco-sweep[cluster]'") from None
    if scheduler:
        try:
            client = Client(scheduler, timeout=f"{timeout}s", set_as_default=False)
        except Exception as exc:
            raise SweepRuntimeError(f"cannot connect to the dask scheduler at {scheduler} "
                                    f"within {timeout:g} s ({_first_line(exc)})") from None
        return client, None
    n = jobs or os.cpu_count() or 1
    cluster = LocalCluster(n_workers=n, threads_per_worker=1, processes=True,
                           dashboard_address=None)
    return Client(cluster, set_as_default=False), cluster


# ----------------------------------------------------------------------------- entry point
def run_sweep(config, jobs: int | None = None, backend: str = "local",
              scheduler: str | None = None, out=None, resume: bool = True,
              progress="auto", simulate: Callable | None = None,
              consolidate_every: float = 5.0, connect_timeout: float = 10.0,
              stream=None) -> SweepReport:
    """Run (or resume) the sweep of ``config`` and write its results file.

    Parameters
    ----------
    config : SweepConfig, mapping, or path of a YAML file
    jobs : int, optional
        Worker processes (local and loky, default: all cores) or tasks in flight (dask,
        default: all worker threads of the cluster).
    backend : {"local", "loky", "dask"}
        "local" (default): worker processes on this machine, forked from this one where that
        is safe (Linux, a single-threaded process: :mod:`sweep.campaign.forked`), else loky's;
        "loky": always joblib's loky workers (new interpreters); "dask": a cluster.
    scheduler : str, optional
        Address of a dask.distributed scheduler (``tcp://host:8786``); dask backend only.
    out : path, optional
        Results file, overriding the config's ``output`` (relative to the cwd).
    resume : bool
        True (default): keep an existing results file of the same config and run only the
        scenes it lacks. False (``--fresh``): move existing results aside to ``<out>.bak``
        and start over. A results file of a *different* config is never overwritten: with
        ``resume`` it is an :class:`InputError`.
    progress : {"auto", "bar", "log", "none"} or callable
        "auto": an updating line on a TTY, one line per scene otherwise. A callable gets a
        dict (done, total, failed, eta, row) after each scene.
    simulate : callable, optional
        Replacement for :func:`sweep.engine.bem.simulate` (module-level, so that it pickles to
        workers); for tests and benchmarks.
    consolidate_every : float
        Seconds between consolidations of the results file (see :mod:`sweep.campaign.store`).
    connect_timeout : float
        Seconds to wait for a dask scheduler.

    Raises
    ------
    InputError
        Invalid config or options, unwritable output, incompatible existing results.
    SweepRuntimeError
        Cluster unreachable, another writer on the same file, a worker crash.
    """
    t_start = time.monotonic()
    cfg = as_config(config)
    if backend not in BACKENDS:
        raise InputError(f"backend must be one of {', '.join(BACKENDS)} (got {backend!r})")
    if jobs is not None:
        jobs = check_int("jobs", jobs, 1, 4096)
    if scheduler is not None and backend != "dask":
        raise InputError("scheduler: an address is only used with backend dask "
                         "(add --backend dask)")
    if scheduler is not None:
        check_scheduler_address(scheduler)
    if not callable(progress) and progress not in PROGRESS_MODES:
        raise InputError(f"progress must be one of {', '.join(PROGRESS_MODES)} "
                         f"(got {progress!r})")
    consolidate_every = check_range("consolidate_every", consolidate_every, 0.0, 1e6)
    connect_timeout = check_range("connect_timeout", connect_timeout, 0.0, 3600.0, lo_open=True)
    path = real_path(cfg.output_path(out))
    check_output_writable(path)
    tasks = cfg.tasks()

    store = ResultStore(path, config_hash=cfg.config_hash, config_name=cfg.name,
                        config_text=cfg.recorded_text, config_source=cfg.source, n_scenes=len(tasks),
                        trajectories=cfg.trajectories, template_row=template_row(cfg),
                        interval=consolidate_every, config=cfg)
    try:
        store.prepare(resume=resume)
    except StoreBusyError as exc:
        raise SweepRuntimeError(str(exc)) from None

    client = cluster = None
    try:
        if backend == "dask":
            client, cluster = _connect_dask(scheduler, jobs, connect_timeout)
        done = store.begin(fresh=not resume)
    except BaseException:
        store.abort()
        _close_dask(client, cluster)
        raise

    spool_dir = store.parts / SPOOL
    # rows a killed sweep's workers had finished and it had not stored (sweep.campaign.spool)
    task_ids = {sid for sid, _ in tasks}
    done |= _unspool(store, spool_dir, task_ids, error_log_path(path))
    # a scene that hit an internal error (a bug, not a result) runs again on resume
    retry = {row["scene_id"] for row in store.rows if row.get("status") == "error"}
    todo = [(sid, scene) for sid, scene in tasks if sid not in done or sid in retry]
    skipped = len(tasks) - len(todo)
    prog = Progress(progress, total=len(tasks), already=skipped, stream=stream)
    if backend in ("local", "loky"):
        n_jobs = min(jobs or os.cpu_count() or 1, max(len(todo), 1))
        forked = backend == "local" and n_jobs > 1 and forked_workers_usable()
        where = (f"on {n_jobs} {'forked' if forked else 'loky'} workers" if n_jobs > 1 else
                 "in this process")
        backend = "fork" if forked else "loky"
    else:
        n_jobs = jobs or -1
        where = f"on dask cluster {scheduler or 'LocalCluster'}"
    if todo:
        prog.message(f"sweep {cfg.name}: {len(tasks)} scenes, {skipped} already done, "
                     f"{len(todo)} to run {where} -> {path}")
    else:
        prog.message(f"sweep {cfg.name}: all {len(tasks)} scenes already done -> {path}")
    if store.backup is not None:
        prog.message(f"previous results moved to {store.backup}")
    copies = cfg.copies_by_unused_n()
    if copies and todo:
        prog.message(f"note: {copies} of the scenes differ from another only in n, which "
                     f"their material (sls, a Prony table) does not use: they compute the "
                     f"same numbers again (give those materials one n in a sub-grid of their "
                     f"own: docs/configs.md)")
    older = older_revision_rows(store.rows, {sid for sid, _ in tasks} - {s for s, _ in todo})
    if older:
        prog.message(f"{path} keeps finished rows of an earlier engine: "
                     f"{revision_counts(older)}; this engine is "
                     f"revision {ENGINE_REVISION} (column engine_revision); use --fresh to "
                     f"compute every row again")
    if store.grown_from and todo:
        prog.message(f"growing {path}: same numerics as the config that wrote it, so its "
                     f"finished scenes are kept and only new ones run ({len(done)} in the "
                     f"file, {store.meta['n_scenes']} in the grown grid)")

    ran = failed = errors = 0
    failed_ids, error_ids = [], []
    error_log = error_log_path(path)
    completed = False
    try:
        if todo:
            warm = simulate is None and _warm_parent(
                prog, [scene for _, scene in todo], cfg.numerics,
                in_workers=backend != "fork" and not (backend == "loky" and n_jobs == 1))
            chunks = dispatch_chunks(todo, cfg.numerics, n_jobs)
            # forked workers start here, before the progress bar's thread (a fork copies
            # one thread only: sweep.campaign.forked)
            results = _results(chunks, cfg, backend, n_jobs, client, simulate, warm,
                               spool_dir if n_jobs > 1 else None)
            prog.start()
            try:
                for row, traj in results:
                    tb = row.pop(TRACEBACK_KEY, None)
                    store.append(row, traj)
                    ran += 1
                    if row.get("status") == "error":
                        errors += 1
                        error_ids.append(row["scene_id"])
                        log_internal_error(error_log, row, tb or "(no traceback)\n")
                    elif row.get("status") != "ok":
                        failed += 1
                        failed_ids.append(row["scene_id"])
                    prog.update(row)
                    store.maybe_consolidate()
            finally:
                with warnings.catch_warnings():  # joblib warns about cancelled tasks
                    warnings.simplefilter("ignore")
                    results.close()
        completed = True
    except KeyboardInterrupt:
        prog.close()
        _unspool(store, spool_dir, task_ids, error_log)
        _finish_store(store)
        raise SweepInterrupted(kept=len(store.rows), total=store.meta["n_scenes"],
                               output=path) from None
    except SystemExit:
        prog.close()
        _unspool(store, spool_dir, task_ids, error_log)
        _finish_store(store)
        raise
    except Exception as exc:
        prog.close()
        _unspool(store, spool_dir, task_ids, error_log)
        _finish_store(store)
        raise SweepRuntimeError(
            f"sweep stopped after {ran} of {len(todo)} scenes ({type(exc).__name__}: "
            f"{_first_line(exc)}); finished scenes are saved in {path}, run the same "
            f"command again to resume") from exc
    finally:
        _close_dask(client, cluster)
    if completed:
        prog.close()
        store.finish()
        spool.clear(spool_dir)
    report = SweepReport(output=path, name=cfg.name, total=len(tasks), skipped=skipped, ran=ran,
                         failed=failed, wall_s=time.monotonic() - t_start, backend=backend,
                         jobs=n_jobs, backup=store.backup, failed_ids=failed_ids,
                         errors=errors, error_ids=error_ids,
                         error_log=error_log if errors else None)
    return report


#: the spool's folder in a results file's parts directory (:mod:`sweep.campaign.spool`)
SPOOL = "spool"


def _unspool(store: ResultStore, spool_dir: Path, wanted: set, error_log: Path) -> set:
    """Store the spooled rows of ``wanted`` scenes that ``store`` lacks, or holds as an
    internal error (an interrupted chunk's finished scenes, or those of a sweep killed with
    its workers), then clear the spool; an internal error's traceback goes to ``error_log``.
    Returns their ids."""
    kept = set()
    for row, traj in spool.read(spool_dir):
        sid = row.get("scene_id")
        # a scene whose stored row is an internal error ran again: its new row replaces it
        retried = store.status(sid) == "error" and row.get("status") != "error"
        if sid in wanted and (not store.holds(sid) or retried) and sid not in kept:
            tb = row.pop(TRACEBACK_KEY, None)
            store.append(row, traj)
            if row.get("status") == "error":
                log_internal_error(error_log, row, tb or "(no traceback)\n")
            kept.add(sid)
    spool.clear(spool_dir)
    return kept


def _finish_store(store: ResultStore) -> None:
    try:
        store.finish()
    except Exception:
        store.abort()


def _close_dask(client, cluster) -> None:
    for obj in (client, cluster):
        if obj is not None:
            try:
                obj.close()
            except Exception:  # pragma: no cover
                pass


def _warm_parent(prog: Progress | None = None, scenes=(), numerics=None,
                 in_workers: bool = False) -> bool:
    """Compile (or load) the Numba kernels once, in the parent, before the workers start;
    True if the workers are to load them too (on their first task), False if the cache is
    cold and no scene of ``scenes`` runs the BEM (:func:`needs_bem_kernels`): a crack-front
    or PB grid compiles nothing. With a current cache and the scenes run in worker processes
    (``in_workers``: new interpreters) the parent loads nothing: only the workers use them, each
    loading them before its first scene's timer (the parent's load was 0.3 s of a warm
    200-scene sweep's 3.0 s on 2 cores: 2.6-2.7 s without it, three runs each, 2026-11-26).

    On a cold cache (the first run after an install or an edit of the kernels) the compile
    takes tens of seconds: ``prog`` then gets a line before and one with its time after.
    Forked workers (``in_workers`` False) inherit what the parent loaded, once for all."""
    global _KERNELS_LOADED
    try:  # lazy: see _prepare_worker
        from ..engine import bem as solver
    except ImportError as exc:
        raise SweepRuntimeError(f"cannot import the solver ({exc})") from None
    cold = not solver.kernels_cached()
    if cold and not needs_bem_kernels(scenes, numerics):
        return False
    if not cold and in_workers:
        return True
    if cold and prog is not None:
        prog.message("compiling kernels (first run only) ...")
    seconds = solver.warm_up()
    _KERNELS_LOADED = True
    if cold and prog is not None:
        prog.message(f"compiling kernels (first run only): done in {seconds:.1f} s")
    return True


def needs_bem_kernels(scenes, numerics) -> bool:
    """Whether any scene runs the BEM's unloading kernels: model "bem" (but an elastic,
    quasi-static scene: the elastic branch), or "auto" where :func:`model_choice` picks the
    BEM. An "auto" scene whose cheaper model misses its tolerance at run time still gets the
    BEM, its kernels compiled on that first call."""
    from ..engine.models import model_choice, wants_quasistatic

    for scene in scenes:
        model = getattr(scene, "model", "bem")
        if model == "bem" and not wants_quasistatic(scene, numerics):
            return True
        if model == "auto" and model_choice(scene, numerics).model == "bem":
            return True
    return False


def run_chunk(scenes, numerics, trajectories: bool = False,
              simulate: Callable | None = None, warm: bool = True, spool_dir=None) -> list:
    """Worker task: :func:`run_scene` on each scene of a dispatch chunk, in order; returns
    the list of their ``(row, trajectory or None)``. With ``spool_dir`` each is also written
    there as its scene ends (:mod:`sweep.campaign.spool`: what an interrupt keeps)."""
    out = []
    for scene in scenes:
        out.append(run_scene(scene, numerics, trajectories, simulate, warm=warm))
        if spool_dir is not None:
            spool.write(spool_dir, *out[-1])
    return out


#: seconds between two reads of the forked workers' spool while no chunk ends
SPOOL_TICK = 0.2


class _ForkedResults:
    """The rows of forked workers (:class:`sweep.campaign.forked.ForkedWorkers`), started on
    creation: an iterator of ``(row, trajectory)`` with the generator's ``close``. With a
    spool each row comes as its scene ends (read from the spool, :data:`SPOOL_TICK`), else
    with its chunk."""

    def __init__(self, chunks, cfg: SweepConfig, n_jobs: int, simulate, warm: bool,
                 spool_dir=None):
        calls = [([scene for _, scene in chunk], cfg.numerics, cfg.trajectories, simulate, warm,
                  spool_dir) for chunk in chunks]
        self._workers = ForkedWorkers(run_chunk, calls, n_jobs)
        self._rows = (self._streamed(spool.Reader(spool_dir)) if spool_dir is not None else
                      (row for rows in self._workers for row in rows))

    def _streamed(self, reader):
        seen = set()
        for rows in self._workers.ticking(SPOOL_TICK):
            # the spool first: a chunk's rows are there before its result
            for row, traj in reader.new() + (rows or []):
                if row["scene_id"] not in seen:
                    seen.add(row["scene_id"])
                    yield row, traj

    def __iter__(self):
        return self

    def __next__(self):
        return next(self._rows)

    def close(self) -> None:
        self._workers.close()


def _results(chunks, cfg: SweepConfig, backend: str, n_jobs: int, client, simulate,
             warm: bool = True, spool_dir=None):
    """``(row, trajectory)`` per scene: chunk by chunk in completion order. Forked workers
    (backend "fork") start at this call; the others at the first row asked for. Local
    workers also spool each row as its scene ends (``spool_dir``, :mod:`sweep.campaign.spool`)."""
    if backend == "fork":
        return _ForkedResults(chunks, cfg, n_jobs, simulate, warm, spool_dir)
    return _joblib_results(chunks, cfg, backend, n_jobs, client, simulate, warm,
                           spool_dir if backend == "loky" else None)


def _joblib_results(chunks, cfg: SweepConfig, backend: str, n_jobs: int, client, simulate,
                    warm: bool = True, spool_dir=None):
    calls = (delayed(run_chunk)([scene for _, scene in chunk], cfg.numerics,
                                cfg.trajectories, simulate, warm, spool_dir)
             for chunk in chunks)
    if backend == "loky" and n_jobs == 1:
        limits = limit_loaded_pools()
        try:
            for chunk in chunks:
                for _, scene in chunk:
                    yield run_scene(scene, cfg.numerics, cfg.trajectories, simulate,
                                    in_worker=False)
        finally:
            if limits is not None:
                limits.restore_original_limits()
        return
    if backend == "loky":
        ctx = parallel_config(backend="loky", inner_max_num_threads=1)
    else:
        ctx = parallel_config(backend="dask", client=client, wait_for_workers_timeout=60)
    with ctx:
        par = Parallel(n_jobs=n_jobs, return_as="generator_unordered", batch_size=1,
                       pre_dispatch="2*n_jobs")
        for rows in par(calls):
            yield from rows
