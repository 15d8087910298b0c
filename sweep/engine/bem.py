"""The single-scene driver: ``simulate(scene, numerics) -> Result``.

Orchestration only; each concept has its module:

1. :mod:`sweep.engine.problem` derives the scene's numbers once (LJ constants, process zone,
   domain, mesh from :mod:`sweep.engine.mesh` with its cached influence matrix, Prony series);
2. :mod:`sweep.engine.initial` solves the relaxed initial state (elastic LJ at delta0 or a0);
3. the unloading kernel ``kernels.solve.unload`` (Prony recursion) or, with
   ``numerics.exact``, :mod:`sweep.engine.exact` (exact hereditary integral);
4. :mod:`sweep.engine.postprocess`: pull-off |min P| (parabola through the samples around the
   minimum), the state there and the crack speed -da/dt;
5. the error estimate (:func:`sweep.engine.resolution.estimate_error`): the pull-off change
   against the same scene at half the resolution in space and time, plus the Prony fit's
   error; a result whose estimate exceeds ``numerics.pull_off_rtol`` is not ``ok``.

A numerical failure never raises: the ``Result`` has ``status="failed"`` and a reason. A
programming error (:func:`sweep.errors.is_internal_error`: TypeError, IndexError, ...) is
not a result: it raises (``sweep run`` records it as status "error"). Invalid input raises :class:`sweep.errors.InputError` when the Scene/Numerics are built.
"""
from __future__ import annotations

import dataclasses
import math
import os
import re
import time
from pathlib import Path

import numpy as np

from ..kernels.solve import (N_STATS, STAT_FACTOR, STAT_ITER, STATUS_LEFT_BAND,
                             STATUS_STEP_LIMIT, Physics, Records, RunState, StepControl,
                             invalidate, set_deadline, unload)
from ..errors import NUMERICAL_ERRORS, is_internal_error
from ..kernels.interface import lj_traction
from ..kernels.jacobian import use_drift_scaled
from ..scene import Numerics, Protocol, Result, Scene
from . import budget
from .budget import OverBudget
from .exact import unload_exact
from .initial import ElasticSolver, relaxed_state
from .postprocess import STATUS_TIME_BUDGET, cycle_work, finish
from .problem import Problem, Refused, derive, material_of, prepare
from .protocol import PHASES, run_phases
from .resolution import estimate_error, refine_advice

#: Newton iterations per solve: a good step converges in 2-5 (quadratic predictor); a solve
#: that needs more is better retried with a smaller step or taken for a fold
MAX_NEWTON_ITER = 12
#: the crack tip must recede by this many (fine) node spacings after the load minimum
#: before a run stops (a lattice dip of the load cannot end it; kernels.solve.stop_reached)
STOP_TRAVEL_SPACINGS = 3.0
#: relative load error of the step predictor below which the step grows beyond
#: numerics.step (up to 8 times) where the load evolves smoothly and the crack tip moves
#: slowly (kernels.solve.next_step); 0 never exceeds numerics.step. At 1e-3 the pull-off
#: and crack speed of the reference scenes move by < 1e-8 and < 3e-7 (relative)
STEP_TOL = 1e-3


def simulate(scene: Scene, numerics: Numerics | None = None) -> Result:
    """Simulate one scene: unload a rigid sphere from a relaxed viscoelastic half-space.

    Parameters
    ----------
    scene : Scene
        Physics: material (n, k), Tabor parameter, initial state, unloading rate.
    numerics : Numerics, optional
        Discretization; default ``Numerics.preset("balanced")``.

    Returns
    -------
    Result
        Pull-off force, state and crack speed at pull-off, counters, trajectory, and the
        error estimate (:mod:`sweep.engine.resolution`).
        ``status`` is "failed" (with ``reason``) if the run could not be completed or its
        error estimate exceeds ``numerics.pull_off_rtol`` (reason "unresolved: ...").
    """
    if numerics is None:
        numerics = Numerics.preset("balanced")
    if not isinstance(scene, Scene):
        raise TypeError("scene must be a sweep.Scene")
    if not isinstance(numerics, Numerics):
        raise TypeError("numerics must be a sweep.Numerics")
    t_start = time.perf_counter()
    with budget.scene_budget(numerics.time_budget_s) as deadline:
        res = _attempt(scene, numerics, deadline)
        if not numerics.exact:
            estimate_error(res, derive(scene, numerics).tip_zone,
                           lambda coarse: _attempt(scene, coarse, deadline))
        elif res.ok:
            res.reason = f"{res.reason}; {EXACT_NOTE}" if res.reason else EXACT_NOTE
    res.wall_s = time.perf_counter() - t_start
    return res


#: what an ``ok`` row of the exact hereditary reference (``numerics.exact``) says of its error:
#: it is the Prony series' reference (no series, no Prony error), and its mesh's error is not
#: estimated (a coarser solve of the quadratic-cost history doubles its cost)
EXACT_NOTE = ("exact hereditary reference: no error estimate (no Prony series; the mesh's "
              "error is not estimated: compare two resolutions)")


def _attempt(scene: Scene, numerics: Numerics, deadline: float = math.inf) -> Result:
    """One solve; where the crack tip leaves the fine band of a graded mesh, again (twice at
    most) on the mesh with the band widened on that side by its width."""
    band = None
    for _ in range(3):
        res = Result(scene=scene, numerics=numerics)
        try:
            budget.check("the BEM's " + ("retry with a wider band" if band else "mesh"))
            pb = prepare(scene, numerics, band)
            left = _simulate(pb, res, deadline)
        except (Refused, OverBudget) as exc:
            res.reason = str(exc)
            return res
        except NUMERICAL_ERRORS as exc:   # a bug (TypeError, ...) is not a result: it raises
            if is_internal_error(exc):
                raise
            res.status = "failed"
            res.reason = f"{type(exc).__name__}: {exc}"
            return res
        if left is None:
            return res
        lo, hi = pb.mesh.band
        width = max(hi - lo, 10 * pb.tip_zone)
        band = (max(lo - width, 0.0), hi) if left == "inner" else (lo, hi + width)
    return res


#: the crack-tip travel (fine spacings) within which a predicted load minimum counts as near
#: (``Numerics.da_max_pulloff`` then bounds the step): the crack-speed fit reads the records
#: within three spacings of the pull-off radius
PULLOFF_ZONE_SPACINGS = 10.0

#: the unloading kernel runs in chunks of this many steps; the wall-time budget is checked
#: between chunks (a resumed chunk restarts the step predictor: a few Newton iterations)
CHUNK_STEPS = 2000


@dataclasses.dataclass
class UnloadingState:
    """Everything an unloading run carries between kernel calls (all arrays on one mesh):
    the gap ``h``, the Prony modal state ``q`` (M, N), the records (t, delta, P, a,
    a_inner) of which the first ``n`` are filled, the next step (units of h0) ``step``,
    the Jacobian cache, the solver counters ``stats``, the traction ``sigma`` of ``h`` and
    the state ``h_prev`` before it (written by the kernel, read on resuming with a process
    zone: its traction depends on the step that made ``h``)."""

    h: np.ndarray
    delta0: float
    q: np.ndarray
    records: list
    n: int
    step: np.ndarray
    cache: tuple
    stats: np.ndarray
    sigma: np.ndarray = None
    h_prev: np.ndarray = None

    @classmethod
    def start(cls, pb: Problem, h_init, delta0: float, cache, stats) -> "UnloadingState":
        """The state at the start of unloading from the relaxed gap ``h_init``; its first
        step a lead-in where the Prony recursion would ring (:func:`ringing_lead_in`)."""
        N = pb.mesh.nodes
        step = np.zeros(3)
        step[0] = ringing_lead_in(pb)
        step[2] = 1.0 if step[0] > 0.0 else 0.0
        return cls(h=np.asarray(h_init, float).copy(), delta0=float(delta0),
                   q=np.zeros((pb.prony_weights.size, N)),
                   records=[np.empty(pb.numerics.max_steps + 1) for _ in range(5)], n=0,
                   step=step, cache=cache, stats=stats, sigma=np.zeros(N),
                   h_prev=np.zeros(N))


#: the Prony recursion's step is a trapezoid in the traction's relaxation: a mode that
#: relaxes in tau_R rings with the factor (1 - x/2)/(1 + x/2), x = dt/tau_R, period two,
#: where the step is long against it (an SLS of k 3e-4 at dt 0.04 tau0: -0.96). A kink in
#: the loading (the unloading's start from rest, a protocol's retraction from its dwell)
#: excites it, and the load alternates step by step for tens of steps: a stop rule fooled
#: by it ended a relaxed start `ok` at 0.55 where its pull-off is 4.2 (n 2.1, k 2.9e-4, mu
#: 2.6, an SLS, rate 2.5, a0 1.9, the accurate preset at band resolution 72; session 51).
#: Where the recursion's most negative amplification at the ordinary step is below this
#: factor, the unloading starts with a lead-in (:func:`ringing_lead_in`)
RINGING_FACTOR = -0.5


def ringing_amplification(weights, times, dt: float) -> float:
    """The most negative real eigenvalue of one step ``dt`` (tau0) of the Prony recursion
    (:mod:`kernels.history`) at a fixed displacement: how a traction error carries to the
    next step (period-two ringing where it is near -1). 1 where there are no modes."""
    c, tau = np.asarray(weights, float), np.asarray(times, float)
    if c.size == 0:
        return 1.0
    x = dt / tau
    e = np.exp(-x)
    b = np.where(np.isinf(tau), 1.0, -np.expm1(-x) / np.where(x > 0.0, x, 1.0))
    ceff = 1.0 - float(np.sum(c * b))
    M = c.size
    T = np.zeros((M + 1, M + 1))
    T[0, 0], T[0, 1:] = -float(np.sum(c * b)) / ceff, c * e / ceff
    for i in range(M):
        T[1 + i] = b[i] * T[0]
        T[1 + i, 1 + i] += e[i]
        T[1 + i, 0] -= b[i]
    return float(np.min(np.linalg.eigvals(T).real))


def ringing_lead_in(pb: Problem) -> float:
    """The first indentation step (h0) of an unloading on ``pb`` where the Prony recursion
    would ring at ``numerics.step`` (:data:`RINGING_FACTOR`): the longest step of a factor-2
    ladder below it whose amplification is not negative (the relaxation's transient damped
    within the step), from which the kernel's lead-in grows the step by
    ``kernels.solve.LEAD_GROWTH`` a step; 0 where no lead-in is needed (the ordinary step)."""
    rate, step = pb.scene.rate, pb.numerics.step
    if pb.prony_weights.size == 0 or not rate > 0.0:
        return 0.0
    if ringing_amplification(pb.prony_weights, pb.prony_times, step / rate) >= RINGING_FACTOR:
        return 0.0
    first = step
    for _ in range(60):
        first *= 0.5
        if ringing_amplification(pb.prony_weights, pb.prony_times, first / rate) >= 0.0:
            break
    return first


def unload_chunk(pb: Problem, run: UnloadingState, tip_range, steps: int,
                 deadline: float = math.inf) -> int:
    """Continue the unloading ``run`` on ``pb``'s mesh by at most ``steps`` time steps (in
    place); returns the kernel's status (STATUS_STEP_LIMIT: the chunk ended, call again).

    ``tip_range`` (a_ref) bounds the crack tip (STATUS_LEFT_BAND when it leaves). The state
    may be carried to another mesh between calls (its arrays interpolated) and continued.
    ``deadline`` (``time.perf_counter()`` seconds) ends the call with STATUS_TIME_BUDGET
    within about one Newton iteration of it: the kernel reads it (a chunk on a large mesh
    lasts minutes), and a run that meets it is not changed by it.
    """
    numerics = pb.numerics
    h_out = np.empty(pb.mesh.nodes)
    if run.sigma is None:       # a state carried to another mesh (tip-following: no process
        run.sigma = np.empty(pb.mesh.nodes)            # zone there): the LJ law's traction
        lj_traction(run.h, pb.h0, pb.c, run.sigma)
        run.h_prev, run.step[1:] = run.h.copy(), 0.0
    # the drift-scaled chord (kernels.jacobian.scale_for_drift) with a process zone, whose
    # settled start leaves the interior's drift as the residual (docs/performance.md); the
    # Lennard-Jones law's unloading keeps the plain chord (it refactorizes 5-14 times a run)
    use_drift_scaled(run.cache, not math.isinf(pb.hdot_c))
    limit = min(run.n + steps, numerics.max_steps)
    da_max_pulloff = (numerics.da_max if numerics.da_max_pulloff is None
                      else numerics.da_max_pulloff)
    control = StepControl(numerics.step, numerics.min_step, numerics.da_max * pb.mesh.spacing,
                          STEP_TOL, numerics.tol, MAX_NEWTON_ITER, limit, pb.stop_mode,
                          STOP_TRAVEL_SPACINGS * pb.mesh.spacing, *tip_range,
                          da_max_pulloff * pb.mesh.spacing,
                          PULLOFF_ZONE_SPACINGS * pb.mesh.spacing)
    set_deadline(run.cache, deadline - time.perf_counter())
    status, run.n = unload(pb.mesh_arrays(),
                           Physics(pb.h0, pb.c, pb.prony_weights, pb.prony_times, pb.scene.rate,
                                   pb.hdot_c, pb.pz_xi, pb.machine_compliance),
                           control, RunState(run.h, run.delta0, run.q, run.n, run.step,
                                             run.sigma, run.h_prev),
                           Records(*run.records, h_out), run.cache, run.stats)
    set_deadline(run.cache, math.inf)
    run.h = h_out
    return int(status)


def _simulate(pb: Problem, res: Result, deadline: float = math.inf) -> str | None:
    """Solve the prepared problem into ``res``. Returns "inner"/"outer" when the crack tip
    left the fine band on that side (``res`` then says so), else None. ``deadline``
    (time.perf_counter() seconds) ends the unloading with the time-budget status."""
    scene, numerics, mesh = pb.scene, pb.numerics, pb.mesh
    r, dr = mesh.r, mesh.spacing
    res.spacing, res.domain_used, res.nodes_used = dr, mesh.domain, mesh.nodes
    res.prony_terms, res.prony_error = int(pb.prony_weights.size), pb.prony_error

    if scene.protocol() is not None:
        return _simulate_protocol(pb, res, deadline)
    el = ElasticSolver(pb.A, r, pb.h0, pb.c, numerics.tol)
    try:
        h_init, delta0 = relaxed_state(el, delta0=scene.delta0, a0=scene.a0,
                                       mesh_key=(mesh.key, mesh.spacing))
        # the unloading starts unfactorized whether or not the relaxed state was cached,
        # so a scene's result does not depend on what the process solved before
        invalidate(el.cache)
    except OverBudget:
        raise
    except RuntimeError as exc:
        res.reason = f"initial state: {exc}"
        return
    res.delta0_result = delta0
    res.a0_result = el.radius(h_init)
    res.a0_inner = el.radius(h_init, 1.0)
    if res.a0_result >= r[-2]:
        res.reason = (f"initial contact radius {res.a0_result:.4g} reaches the mesh edge "
                      f"(domain {mesh.domain:.4g})")
        return
    if res.a0_result <= 0.0:
        res.reason = no_contact_reason(scene, res.a0_result)
        return

    stats = el.stats.copy()
    min_travel = STOP_TRAVEL_SPACINGS * dr
    if numerics.exact:
        out = [np.empty(numerics.max_steps + 1) for _ in range(5)]
        status, n = unload_exact(pb, h_init, delta0,
                                 material_of(scene) if scene.k < 1.0 else None, min_travel, out,
                                 stats)
    else:
        run = UnloadingState.start(pb, h_init, delta0, el.cache, stats)
        status = _unload(pb, run, deadline)
        n, out = run.n, run.records
    t, delta, P, a, a_inner = (x[:n].copy() for x in out)
    res.trajectory = {"t": t, "delta": delta, "P": P, "a": a, "a_inner": a_inner}
    return _finish(pb, res, status, stats)


def _unload(pb: Problem, run: UnloadingState, deadline: float) -> int:
    """The unloading kernel in chunks of CHUNK_STEPS until it ends, or the deadline does."""
    start = int(run.stats[STAT_FACTOR])
    while True:
        status = unload_chunk(pb, run, pb.tip_range, CHUNK_STEPS, deadline)
        budget.check_work(int(run.stats[STAT_FACTOR]) - start, "the unloading")
        if status != STATUS_STEP_LIMIT or run.n > pb.numerics.max_steps:
            return status
        if time.perf_counter() > deadline:
            return STATUS_TIME_BUDGET


def _finish(pb: Problem, res: Result, status: int, stats,
            retraction_from: int = 0) -> str | None:
    """The counters and the outcome of a run whose trajectory ``res`` holds: "inner"/"outer"
    where the crack tip left the fine band, else None (:func:`finish`; the pull-off and the
    state at it are read on the records from ``retraction_from`` on)."""
    a = res.trajectory["a"]
    dr, n = pb.mesh.spacing, len(a)
    min_travel = STOP_TRAVEL_SPACINGS * dr
    res.steps = n - 1
    res.newton_iterations = int(stats[STAT_ITER])
    res.factorizations = int(stats[STAT_FACTOR])
    if status == STATUS_LEFT_BAND:
        res.reason = (f"the crack tip left the fine band {pb.mesh.band[0]:.3g}..{pb.mesh.band[1]:.3g}"
                      f" of the graded mesh (a = {a[-1]:.4g})")
        return "inner" if a[-1] < pb.tip_range[0] else "outer"
    finish(res, status, res.trajectory, dr, min_travel, pb.scales,
           advice=refine_advice(pb.numerics),
           remeshed=(retraction_from,) if retraction_from > 0 else (),
           machine_stiffness=pb.scene.machine_stiffness,
           first=retraction_from)
    check_prony_window(pb, res)
    return None


def check_prony_window(pb: Problem, res: Result) -> None:
    """Fail ``res`` where its run went past the window its Prony series was fitted on
    (``pb.prony_t_max``) and the series' compliance there is not the material's within the
    series' own tolerance (the larger of ``prony_rtol`` and its measured error; the MPL's or
    SLS's closed form at 16 times from the window's end to the run's): the error estimate,
    whose solves share the series, would not see it. A window caps at WINDOW_T_MAX, and a slow
    run past it is fine where the material has crept all the way (measured on three scenes of
    the random bem sample at rates 2e-4-1e-3, run to 7e4-4e7 tau0: 0 to 4.4e-5); a protocol's
    approach timed at its retraction's speed was not (compliance 25-54 % off, a slow
    approach's pull-off 36 % low; docs/design.md)."""
    t = res.trajectory["t"] if res.trajectory else ()
    if not (len(t) and t[-1] > pb.prony_t_max):
        return
    times = np.geomspace(pb.prony_t_max, t[-1], 16)
    exact = material_of(pb.scene).creep_compliance(times)
    fitted = 1.0 - np.exp(-times[:, None] / pb.prony_times[None, :]) @ pb.prony_weights
    error = float(np.max(np.abs(fitted / exact - 1.0)))
    if error <= max(pb.numerics.prony_rtol, pb.prony_error):
        return
    res.status, res.error_estimate = "failed", float("nan")
    res.reason = (f"the run reached t = {t[-1]:.4g} tau0, past the window its Prony series was "
                  f"fitted on (to {pb.prony_t_max:.4g} tau0), where the series' compliance is "
                  f"{error:.2g} off the material's; an engine estimate missed: please report "
                  f"the scene")


def _simulate_protocol(pb: Problem, res: Result, deadline: float):
    """A scene with a test protocol (:mod:`sweep.engine.protocol`): approach and dwell, then
    the unloading kernel from the dwell's last state, its modes and its records. The row's
    initial state (``a0_result``, ``delta0_result``, ``a0_inner``) is the dwell's last, the
    retraction's start; ``hysteresis_energy`` the work of the whole path (to the pull-off,
    :func:`sweep.engine.postprocess.finish`); the trajectory's
    ``phase`` says which phase made each record."""
    stats = np.zeros(N_STATS, dtype=np.int64)
    try:
        march = run_phases(pb, pb.scene.protocol(), stats)
    except OverBudget:
        raise
    except RuntimeError as exc:
        res.reason = f"protocol: {exc}"
        return None
    rec = march.records
    n0 = len(rec["t"])
    res.delta0_result, res.a0_result, res.a0_inner = march.delta, rec["a"][-1], rec["a_inner"][-1]
    if res.a0_result >= pb.mesh.r[-2]:
        res.reason = (f"the contact at the preload, radius {res.a0_result:.4g}, reaches the "
                      f"mesh edge (domain {pb.mesh.domain:.4g})")
        return None
    run = retraction_start(pb, march, stats)
    status = _unload(pb, run, deadline)
    join_phases(res, march, run)
    # the pull-off is read on the retraction only (its first record the dwell's last state):
    # the approach passed the same radii, and a crack-speed fit over the records near the
    # pull-off's radius took them in (0.056 against 0.051 a_ref/tau0 after a dwell long
    # enough to relax, SLS k 0.2)
    return _finish(pb, res, status, stats, retraction_from=n0 - 1)


def retraction_start(pb: Problem, march, stats) -> UnloadingState:
    """The retraction of a test protocol: an unloading from the march's (the dwell's) last
    state on ``pb``'s mesh, its record 0, its Prony modes and traction; its stop rule and
    pull-off see the retraction's records only."""
    rec = march.records
    invalidate(march.cache)
    run = UnloadingState.start(pb, march.h, march.delta, march.cache, stats)
    for i, key in enumerate(("t", "delta", "P", "a", "a_inner")):
        run.records[i][0] = rec[key][-1]
    run.n, run.q, run.sigma, run.h_prev = 1, march.q, march.sigma, march.h_prev
    run.step[0], run.step[2] = _retraction_first_step(pb, march, ringing=run.step[0])
    return run


def join_phases(res: Result, march, run: UnloadingState) -> None:
    """``res``'s trajectory: the march's records, then the retraction's (``run``) from its
    record 1, with ``phase`` (:data:`sweep.engine.protocol.PHASES`); and the hysteresis
    energy of the whole recorded path (:func:`sweep.engine.postprocess.cycle_work`; a
    pull-off row's ends at its pull-off, :func:`sweep.engine.postprocess.finish`)."""
    rec, n = march.records, run.n
    res.trajectory = {key: np.concatenate([np.asarray(rec[key][:-1], float), x[:n]])
                      for key, x in zip(("t", "delta", "P", "a", "a_inner"), run.records)}
    res.trajectory["phase"] = np.concatenate(
        [np.asarray(rec["phase"], float), np.full(n - 1, float(PHASES["retract"]))])
    res.hysteresis_energy = cycle_work(res.trajectory)


def _retraction_first_step(pb: Problem, march, ringing: float = 0.0) -> tuple[float, float]:
    """(the retraction's first indentation step in h0, the lead-in flag): the march's last
    time step at the retraction's rate (the larger of its last two: the approach's last is cut
    to end at the preload), where that is shorter than ``numerics.step``; the unloading kernel
    then grows it by LEAD_GROWTH a step up to ``numerics.step`` (:func:`kernels.solve.unload`).
    Where the Prony recursion would ring (``ringing``, :func:`ringing_lead_in`'s step, 0 where
    it would not), the smaller of that step and the march's. Else ``numerics.step`` and no
    lead-in.

    A retraction that starts right after a fast approach (no dwell, or a short one) starts
    from an unrelaxed contact whose load relaxes on the approach's time scale. A first step of
    ``numerics.step`` is then orders of magnitude longer than the approach's, and the load
    jumped across the relaxation: n 1.617, k 0.01603, mu 0.9055, approach rate 928.1, preload
    11.59, no dwell, rate 0.03025 fell from 11.59 to -2.67 in one step of 0.052 tau0 (75
    times the approach's last), a spurious minimum 1.5 times the pull-off (-1.76 at t = 52,
    which steps ten times shorter find)."""
    dt = max(march.dt_prev, march.dt_prev2)
    step = pb.scene.rate * dt
    # ``ringing``: the step the recursion does not ring at (ringing_lead_in, 0 where it
    # does not ring), as UnloadingState.start found it
    if ringing > 0.0 and not 0.0 < step < ringing:
        return ringing, 1.0
    if 0.0 < step < pb.numerics.step:
        return step, 1.0
    return pb.numerics.step, 0.0


def kernels_cached() -> bool:
    """Whether every Numba kernel module has a cache index at least as new as its source, so
    that :func:`warm_up` loads the kernels rather than compiling them (about 40 s on a cold
    cache). A guess from file names and times (``$NUMBA_CACHE_DIR`` or the kernels'
    ``__pycache__``), used only to tell the user what a silent first start is doing."""
    from .. import kernels

    src_dir = Path(kernels.__file__).resolve().parent
    env = os.environ.get("NUMBA_CACHE_DIR", "").strip()
    root = Path(env) if env else src_dir / "__pycache__"
    if not root.is_dir():
        return False
    for src in src_dir.glob("*.py"):
        try:
            if not re.search(r"^@njit", src.read_text(encoding="utf-8"), re.M):
                continue
            stamps = [p.stat().st_mtime for p in root.rglob(f"{src.stem}.*.nbi")]
            if not stamps or max(stamps) < src.stat().st_mtime:
                return False
        except OSError:
            return False
    return True


def no_contact_reason(scene: Scene, radius: float) -> str:
    """Why a run has no initial contact, for the initial state the scene gave."""
    if scene.a0 is not None:
        return (f"no contact in the initial state: the relaxed state solved for a0 = "
                f"{scene.a0:g} has contact radius {radius:.3g} (no stable contact of that "
                f"radius was found)")
    return (f"no contact in the initial state (delta0 = {scene.delta0:g} is below the "
            f"jump-in)")


def warm_up() -> float:
    """Compile (or load from the Numba cache) the kernels on a tiny scene; returns seconds.

    The march of a test protocol (:mod:`sweep.engine.protocol`, its kernels in
    ``kernels.protocol``) runs on the same problem, a short approach and dwell at force
    (a scene with a protocol would fit a Prony series of its own, over a wider time window).

    Raises RuntimeError if the warm-up scene itself fails (a broken installation).
    """
    t0 = time.perf_counter()
    scene = Scene(n=0.8, k=0.5, mu=3.24, a0=1.5, rate=10.0)
    for mesh in ("uniform", "graded"):
        numerics = Numerics(mesh=mesh, nodes=80, domain=3.0, step=0.5, da_max=2.0,
                            prony_rtol=1e-2, tol=1e-8, pull_off_rtol=0.0)
        res = simulate(scene, numerics)
        if not res.ok:
            raise RuntimeError(f"warm-up scene failed: {res.reason}")
    run_phases(prepare(scene, numerics), Protocol(approach_rate=10.0, preload=1.0, dwell=0.5),
               np.zeros(N_STATS, dtype=np.int64))
    return time.perf_counter() - t0
