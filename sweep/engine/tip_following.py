"""Viscoelastic unloading on a mesh refined around the crack tip that follows it.

At a large Tabor parameter the process zone l0 = 1.693/mu^2 (a_ref) is tiny (1.9e-3 at mu =
30, 1.7e-4 at mu = 100) and a fixed graded mesh, fine over the whole band the tip sweeps
(from a0 down to below the pull-off radius), needs 10^4-10^5 nodes. Here only a *window*
around the crack tip is fine (spacing l0 / ``band_resolution``, :func:`sweep.engine.mesh.graded_mesh`
with the window as its band, element lengths growing by ``grading`` outside it), and the
mesh is rebuilt when the tip leaves the window:

1. the window is placed with the tip ``behind`` process zones from its trailing end (the
   cohesive zone and the recent wake of the Prony modes stay fine) and ``ahead`` zones of
   room in the direction the tip moves (inward while the contact shrinks);
2. the unloading kernel runs until the tip leaves the window less TIP_MARGIN_ZONES l0
   (``kernels.solve.STATUS_LEFT_BAND``);
3. a new mesh is built with the window moved to the tip and the state is carried over
   (:func:`transfer`): the gap ``h`` by a cubic spline (every mesh lies on the lattice of
   the fine spacing, so nodes common to both meshes keep their values exactly), the Prony
   modal state ``q`` as displacements (A (sigma - q_i), smooth, interpolated and mapped
   back through the new influence matrix), then the gap is re-equilibrated on the new
   mesh at frozen time (with a process zone, under the last step's law, the state before it
   carried too); the records continue and the kernel resumes
   (:func:`sweep.engine.bem.unload_chunk`). Each re-meshing up to the pull-off must leave the
   load continuous (:func:`remesh_jump`), else the run ends failed with the reason.

The cost is set by the window (a few hundred nodes, whatever a0) and by the number of time
steps (the tip moves at most ``da_max`` spacings per step); each new mesh costs one
influence-matrix assembly (about 1 s at 700 nodes).

Units and conventions of docs/design.md section 2.
"""
from __future__ import annotations

import dataclasses
import math
import time
import types

import numpy as np
import scipy.linalg
from scipy.interpolate import CubicSpline
from scipy.optimize import brentq

from ..kernels.solve import (EASY_STEPS, N_STATS, SMOOTH_STEP_FACTOR, STAT_FACTOR, STAT_ITER,
                           STATUS_LEFT_BAND, STATUS_STEP_LIMIT, invalidate, new_jacobian_cache,
                           newton)
from ..kernels.interface import (ZONE_RATE, ZONE_SIZE, ZONE_SMOOTH, ZONE_XI, Interface,
                                 lennard_jones, lj_traction, smoothing_rate, traction)

from ..scene import Numerics, Result, Scene
from . import budget
from .budget import OverBudget
from .crack_front import crack_front_advice
from .bem import (CHUNK_STEPS, STOP_TRAVEL_SPACINGS, UnloadingState, check_prony_window,
                  join_phases, no_contact_reason, retraction_start, unload_chunk)
from .initial import ElasticSolver, cached_state, relaxed_state
from .mesh import WINDOW_AHEAD_ZONES, WINDOW_BEHIND_ZONES, band_nodes, tip_window
from .postprocess import STATUS_TIME_BUDGET, finish
from .problem import Refused, derive, first_contact_radius, jkr_radius, material_of, prepare
from .protocol import DWELL_CHUNK_STEPS, DWELL_DA_FACTOR, run_phases
from .quasistatic import ElasticBranch, fold_refusal, state_at
from .resolution import estimate_error

#: Newton tolerance (units of h0) of a first relaxed solve where the numerics' one stalls
LOOSE_TOL = 1e-4
#: time steps of the probe after which a run first estimates what it still needs (then
#: again after every chunk, :func:`_probe`)
PROBE_STEPS = 200
#: after the probe a run ends early on its time budget only when the estimated time it
#: still needs exceeds the time left by this factor (the probe's cost per step includes the
#: start's factorizations: 80 ms per step over the first 200 steps of mu = 30, a0 = 10,
#: rate 1e-4); after later chunks by any factor (their cost per step is the run's)
TIME_MARGIN = 2.0
#: most meshes of one run (a run that needs more ends failed with the reason)
MAX_MESHES = 5000
#: a re-meshing up to the pull-off must leave the load continuous: the load change over the
#: first step on a new mesh may exceed REMESH_JUMP_STEPS times the change over the
#: neighbouring steps by at most ``rtol`` |P| (rtol: a quarter of the preset's pull-off
#: tolerance, at least REMESH_JUMP_RTOL); else the run ends failed with the reason. (The
#: load on two meshes differs by their discretization error; where the mesh outside the
#: fine window is too coarse for the carried state, much more.)
REMESH_JUMP_STEPS = 5.0
REMESH_JUMP_RTOL = 1e-3
#: a step of a protocol's march moves the crack tip by at most this many ``da_max`` spacings
#: (the dwell's bound; the approach's is smaller): :class:`MarchWindow` bounds its chunks by it
MARCH_TIP_STEP = DWELL_DA_FACTOR
#: Newton iterations of the re-equilibration after a state transfer (:func:`transfer`)
REEQUILIBRATE_ITER = 30


def fold_advice(scene) -> str:
    """What to change when the tip-following mesh finds no equilibrium before the pull-off of
    ``scene``: the band resolution, and the crack-front model where it runs the scene."""
    return ("raise band_resolution (the fine spacing is the tip zone / band_resolution)"
            + crack_front_advice(scene))


def window_problem(scene, numerics, tip, zone, ahead, behind, direction=-1):
    """The prepared problem on the mesh whose fine window is around the crack tip at ``tip``
    (:func:`sweep.engine.mesh.tip_window`; ``direction`` the way the tip moves)."""
    return prepare(scene, numerics, tip_window(tip, zone, ahead, behind, direction),
                   window=True)


def remesh_jump(P: np.ndarray, m: int, rtol: float = REMESH_JUMP_RTOL) -> float | None:
    """The load jump at record ``m`` (the first on a new mesh) when it is not continuous
    with its neighbours (see REMESH_JUMP_STEPS), else None."""
    if m < 2 or m + 1 >= P.size:
        return None
    jump = abs(P[m] - P[m - 1])
    typical = max(abs(P[m - 1] - P[m - 2]), abs(P[m + 1] - P[m]))
    if jump > REMESH_JUMP_STEPS * typical + rtol * abs(P[m - 1]):
        return float(jump)
    return None


def _continuity(scene, run, remeshed_at: list, rtol: float) -> str:
    """Check (and drop from ``remeshed_at``) the re-meshings whose neighbouring records now
    exist; the reason of a failure when one up to the load minimum so far made the load
    jump (:func:`remesh_jump`), else ""."""
    P, a = run.records[2][:run.n], run.records[3][:run.n]
    i_min = int(np.argmin(P))
    while remeshed_at and remeshed_at[0] + 1 < run.n:
        m = remeshed_at.pop(0)
        if m > i_min + 1:       # after the load minimum: the pull-off is already behind
            continue
        jump = remesh_jump(P, m, rtol)
        if jump is not None:
            return (f"re-meshing at a = {a[m - 1]:.4g} made the load jump by {jump:.3g} (from "
                    f"{P[m - 1]:.4g}; tolerance {rtol:g} |P|): the mesh outside the fine window "
                    f"cannot carry the state; use the fixed crack band (raise max_nodes)"
                    f"{crack_front_advice(scene)}")
    return ""


def indentation_travel(scene: Scene, delta0: float, loading_speed: float) -> float:
    """Least indentation travel (d_ref) of an unloading from ``delta0`` to the pull-off:
    D = Cbar(D / (rate h0)) max(delta0, 0), with Cbar(t) = (1/t) int_0^t Chat the mean
    compliance of a ramp of duration t (tau0); ``loading_speed`` = rate h0 (d_ref/tau0,
    :attr:`sweep.engine.problem.Scales.loading_speed`).

    Relaxed (slow) the indentation falls from delta0 to the relaxed pull-off, below 0 (JKR:
    -0.51 at mu = 10); faster, the substrate answers a load change with less compliance, at
    least Chat(0) = k, so the indentation travels less for the same loss of load (a frozen
    contact, k = 1e-4 at rate 1e9: 0.028 of 220). Measured D / this estimate on eight
    scenes at mu = 10-30 (k 1e-4 to 0.5, rates 1e-4 to 1e9): 1.005-1.61, never below 1.
    """
    full = max(delta0, 0.0)
    if full == 0.0 or scene.k >= 1.0:
        return full
    mat = material_of(scene)

    def excess(D):
        t = D / loading_speed
        return D - float(mat.integrated_compliance(t)) / t * full

    # the mean compliance is at least Chat(0) = k: excess < 0 at k full / 2 (a bracket at a
    # fixed 1e-12 full was none for k below 1e-12, and brentq raised)
    return full if excess(full) <= 0.0 else float(brentq(excess, 0.5 * scene.k * full, full))


@dataclasses.dataclass
class StepEstimate:
    """How many time steps a run needs at least, and why (see :func:`estimate_steps`)."""

    steps: int
    tip_travel: float         # a_ref, the crack tip's least recession
    tip_step: float           # a_ref, the most it moves per step (da_max fine spacings)
    tip_steps: int
    travel: float             # d_ref, the indentation's least travel
    step: float               # d_ref, the indentation step assumed
    travel_steps: int

    def describe(self) -> str:
        return (f"the crack tip recedes at least {self.tip_travel:.3g} a_ref at most "
                f"{self.tip_step:.2g} per step "
                f"({self.tip_steps} steps), the indentation falls at least {self.travel:.4g} "
                f"d_ref in steps from {self.step:.3g}, doubling at most every {EASY_STEPS} "
                f"({self.travel_steps} steps)")


def estimate_steps(scene: Scene, numerics: Numerics, delta: float, a: float,
                   delta_start: float, a_start: float, step: float) -> StepEstimate:
    """Least number of further time steps of a run now at indentation ``delta`` and
    contact radius ``a`` that started at (``delta_start``, ``a_start``), with indentation
    steps from ``step`` (d_ref) on, growing no faster than the kernel's step control lets
    them (:func:`least_steps`): the indentation must fall to delta_start -
    :func:`indentation_travel`, and the crack tip at least to the relaxed JKR radius there
    (a frozen contact keeps its radius, a relaxed one follows JKR), at most ``da_max``
    fine spacings per step."""
    scales = derive(scene, numerics)
    D = indentation_travel(scene, delta_start, scales.loading_speed)
    a_end = min(jkr_radius(delta_start - D), a_start)
    tip = max(a - a_end, 0.0)
    da = numerics.da_max * scales.tip_zone / numerics.band_resolution
    rest = max(delta - (delta_start - D), 0.0)
    largest = SMOOTH_STEP_FACTOR * numerics.step * scales.h0
    tip_steps, travel_steps = int(math.ceil(tip / da)), least_steps(rest, step, largest)
    return StepEstimate(steps=max(tip_steps, travel_steps), tip_travel=tip, tip_step=da,
                        tip_steps=tip_steps, travel=rest, step=step, travel_steps=travel_steps)


def least_steps(travel: float, step: float, largest: float) -> int:
    """The fewest indentation steps that cover ``travel`` (d_ref) starting at ``step``: the
    kernel's step control (:func:`sweep.kernels.solve.next_step`) doubles a step after
    EASY_STEPS steps in a row at most, up to ``largest`` (SMOOTH_STEP_FACTOR times
    ``numerics.step``). A run's largest step so far is no bound of its later ones: a
    retraction right after a fast approach takes steps of 1e-6 of its largest while the load
    relaxes on the approach's time scale, then grows them (a protocol at mu 14.6, rate 0.025
    after an approach at 40.5, was refused as needing 338208 steps and ran in 5296)."""
    if travel <= 0.0:
        return 0
    step = max(min(step, largest), 1e-300)
    steps = 0
    while step < largest and travel > EASY_STEPS * step:
        travel -= EASY_STEPS * step
        steps += EASY_STEPS
        step = min(2.0 * step, largest)
    return steps + int(math.ceil(travel / step))


def transfer(run, old, new, form: str = "auto") -> None:
    """Carry the state of an unloading run from the mesh of the prepared problem ``old`` to
    that of ``new`` in place, with a new Jacobian cache; records, step and counters stay.

    The displacement of an accepted state is u = A (sigma - sum_i c_i q_i) (docs/design.md
    section 4; Prony modes q_i, traction sigma = sigma_LJ(h), sum_i c_i = 1 - k with
    k = Chat(0)).

    1. The gap ``h`` is interpolated by a cubic spline (exact at common nodes).
    2. The modes are carried as displacements, which are smooth (the influence matrix
       integrates): interpolated by a cubic spline and mapped back through the new
       influence matrix. Interpolating q_i itself is wrong: the history keeps the sharp
       traction of every cohesive zone the tip has passed, which the coarse mesh behind
       the window samples at its nodes (n = 0.8, k = 0.1, a0 = 3, rate 10^2.5: the load
       jumped by 29 % at mu = 15 and 124 % at mu = 30 at the first re-meshing).
    3. The gap is re-equilibrated on the new mesh at frozen time; without it the kernel
       takes the change from the interpolated to the equilibrium traction for the
       traction increment of its first step (measured: a load jump of 2.3 %). With a
       process zone the state before the last step (``run.h_prev``) is carried as the gap
       is, the equilibrium is that of the last step's law (its opening rate by backward
       Euler over ``run.step[1]``), and the run resumes from the traction under that law
       (``run.sigma``) and the carried ``h_prev``.

    ``form`` says which part of the state is carried and how the traction adjusts:

    * "relaxed": A q_i is carried, the traction adjusts with the relaxed compliance 1;
    * "glassy": A (sigma - q_i) (the history mode i has forgotten) is carried, the
      traction adjusts with the glassy compliance k and every mode takes the change (a
      step of zero length of the kernel);
    * "auto" (default): relaxed, else glassy where its Newton solve fails (a state beyond
      the relaxed pull-off at a fold of the discrete path: n = 0.8, k = 0.1, a0 = 3, rate
      10^2.5, mu = 30 stalled at 1.3e-4 h0 near the load minimum).

    The two forms differ by how the discretization change of the current traction is
    taken up: on that scene at mu = 6, 8 meshes of a narrow window, the pull-off is the
    fixed band's to 1.4e-5 (relaxed) and 7.2e-5 (glassy); at mu = 15 and 30 the two agree
    to 1e-5. Where neither converges the interpolated state is kept (relaxed form) and
    the caller's load continuity check judges the result.
    """
    old_r, new_r = old.mesh.r, new.mesh.r
    # the spline passes through its knots only to rounding (which depends on the BLAS
    # kernels of the CPU): the common nodes take their old gap exactly
    _, i_old, i_new = np.intersect1d(old.mesh.lattice, new.mesh.lattice, return_indices=True)

    def gap(h_old):
        h = CubicSpline(old_r, h_old)(new_r)
        h[i_new] = h_old[i_old]
        return np.maximum(h, 0.5 * float(np.min(h_old)))

    zone = _last_step_law(run, old)
    h = gap(run.h)
    run.cache = new_jacobian_cache(new_r.size)
    if zone is None:
        run.sigma = None    # the LJ law's traction on the new mesh (bem.unload_chunk)
        law = lennard_jones(new.h0, new.c, new_r.size)
        sigma_old = np.empty(old_r.size)
        lj_traction(run.h, old.h0, old.c, sigma_old)
    else:
        # the process zone's traction depends on the step that made the state: the state
        # before it is carried too, and the new mesh's state is solved with the last step's
        # law (the opening rate over it, backward Euler: re-equilibrated at frozen time)
        run.h_prev = gap(run.h_prev)
        law = Interface(new.h0, new.c, run.h_prev, zone)
        sigma_old = run.sigma
    sigma = np.empty(new_r.size)
    traction(h, law.h_old, law.zone, law.h0, law.c, sigma)

    def carry(h, q):            # the new mesh's state; with a process zone, its traction
        run.h, run.q = h, q     # under the last step's law, which the kernel resumes from
        if zone is not None:
            run.sigma = np.empty(new_r.size)
            traction(h, law.h_old, law.zone, law.h0, law.c, run.sigma)

    if run.q.shape[0] == 0:
        carry(h, np.zeros((0, new_r.size)))
        return
    lu = scipy.linalg.lu_factor(new.A)

    def carried(history):       # (M, N_old) tractions -> the same displacements, new mesh
        U = CubicSpline(old_r, old.A @ history.T, axis=0)(new_r)
        return scipy.linalg.lu_solve(lu, U).T

    forms = ("relaxed", "glassy") if form == "auto" else (form,)
    q_first = None
    for name in forms:
        if name == "relaxed":
            q = np.ascontiguousarray(carried(run.q))
        else:
            q = np.ascontiguousarray(sigma[None, :] - carried(sigma_old[None, :] - run.q))
        q_first = q if q_first is None else q_first
        if run.n == 0:
            break
        if name == "relaxed":
            ceff, H = 1.0, new.prony_weights @ q
        else:
            ceff = 1.0 - float(np.sum(new.prony_weights))           # Chat(0)
            H = new.prony_weights @ q - np.sum(new.prony_weights) * sigma
        h_eq = _reequilibrate(run, new, h, ceff, np.ascontiguousarray(H), law)
        if h_eq is not None:
            if name == "glassy":            # every mode takes the change of traction
                sigma_eq = np.empty(new_r.size)
                traction(h_eq, law.h_old, law.zone, law.h0, law.c, sigma_eq)
                q += (sigma_eq - sigma)[None, :]
            carry(h_eq, q)
            return
    carry(h, q_first)


def _last_step_law(run, pb):
    """The process zone's state (:data:`sweep.kernels.interface.Interface`'s ``zone``) over
    the run's last step on ``pb``'s mesh, its opening rate by backward Euler from the carried
    state before it (``run.h_prev``) over that step (``run.step[1]``); None without a process
    zone, or before a step was taken (the LJ law at rest)."""
    if math.isinf(pb.hdot_c) or not run.step[1] > 0.0:
        return None
    zone = np.zeros(ZONE_SIZE)
    zone[ZONE_RATE] = 1.0 / (pb.hdot_c * float(run.step[1]))
    zone[ZONE_XI] = pb.pz_xi
    zone[ZONE_SMOOTH] = smoothing_rate(pb.pz_xi)
    return zone


def _reequilibrate(run, new, h, ceff, H, law):
    """The gap on the mesh of ``new`` in equilibrium with u = A (ceff sigma - H) at the
    indentation of the last record under the interface ``law`` (Newton from ``h``), or None
    if it does not converge."""
    g = -float(run.records[1][run.n - 1]) + new.h0 + 0.5 * new.mesh.r**2
    h_eq = h.copy()
    stats = run.stats if run.stats is not None else np.zeros(N_STATS, dtype=np.int64)
    cache = new_jacobian_cache(h.size)
    budget.arm(cache)
    ok = newton(h_eq, g, new.A, ceff, H, law,
                new.numerics.tol * new.h0, REEQUILIBRATE_ITER, cache, stats)
    if not ok:
        budget.check("the tip-following mesh's re-equilibration")
    return h_eq if ok else None


def branch_state(scene: Scene, band_resolution: float = 16.0, domain: float | None = None):
    """The relaxed elastic equilibrium at contact radius ``scene.a0`` on the quasi-static
    branch (:class:`sweep.engine.quasistatic.ElasticBranch`, which fixes the radius, not the
    indentation), on a mesh as fine as the window's (``band_resolution`` spacings per
    process zone, 8 zones each side) out to ``domain`` (the window mesh's, so that the gap
    is interpolated, never extrapolated): (nodes r, gap h, indentation delta), or None if
    it was not found.

    Raises :class:`sweep.engine.problem.Refused` where a0 lies below the displacement-controlled
    fold of the branch (JKR: a = 0.5): the state exists but is unstable (the indentation
    decreases as the radius grows), so no relaxed state can be held there.
    """
    a0 = scene.a0
    br = ElasticBranch(scene.mu, a0, 0.5 * a0, zone_resolution=band_resolution, zone=8.0,
                       domain=domain)
    state = state_at(br, a0)
    if state is None:
        return None
    h_b, d, below = state
    if below:
        raise Refused(fold_refusal(scene.mu, a0))
    return a0 * br.x, h_b, d


def initial_state(el: ElasticSolver, scene: Scene, branch=None):
    """The relaxed state (gap, indentation) of a scene on the window mesh of ``el``.

    From a0: the equilibrium at contact radius a0 on the quasi-static branch (``branch``,
    :func:`branch_state`), carried to the mesh and polished by Newton at its indentation,
    then bracketed and bisected on the indentation to the radius a0 on this mesh
    (warm-started solves; the tip stays in the fine window): to a0 or, where the tip is
    pinned between nodes (a(delta) a staircase), within two fine spacings
    (``Result.a0_result`` says where), else RuntimeError with the reason. A direct Newton
    solve from the JKR gap, as :func:`sweep.engine.initial.relaxed_state` does, can converge to a
    state whose tip sits on the coarse mesh outside the window at large mu, and its
    continuation costs a dense factorization per solve. From delta0:
    :func:`sweep.engine.initial.relaxed_state`.
    """
    def solve(d_new, guess):
        # Newton to the numerics' tolerance; where it stalls (large mu: the LJ stiffness
        # c/h0 makes the Jacobian ill-conditioned), first to 1e-4 h0, then on from there
        ok, h_new = el.solve(d_new, guess)
        if not ok:
            tol, el.tol = el.tol, max(el.tol, LOOSE_TOL)
            ok, h_new = el.solve(d_new, guess)
            el.tol = tol
            if ok:
                ok_fine, h_fine = el.solve(d_new, h_new)
                h_new = h_fine if ok_fine else h_new
        return ok, h_new

    if branch is not None:
        a0 = scene.a0
        r_b, h_b, d = branch
        ok, h = solve(d, np.maximum(CubicSpline(r_b, h_b)(el.r), 0.3 * el.h0))
        if not ok:
            raise RuntimeError(f"no equilibrium on the window mesh at the branch state of "
                               f"a0 = {a0:g} (Newton stalls on this window at large mu; "
                               f"another band_resolution may start it: 16 (the balanced "
                               f"preset) where the fast preset's 9 fails at mu 8-12, 8 at mu "
                               f"100, a0 1.2; model auto answers with the crack-front model)")
        spacing = float(np.min(np.diff(el.r)))
        best = [abs(el.radius(h) - a0), h, d]

        def radius_at(d_new, h_from, d_from):
            ok, h_new = solve(d_new, np.maximum(h_from - (d_new - d_from), 0.3 * h_from))
            if not ok:
                return None, None
            f_new = el.radius(h_new) - a0
            if abs(f_new) < best[0]:
                best[:] = [abs(f_new), h_new, d_new]
            return f_new, h_new

        # bracket a0 in delta (the radius grows with the indentation on the stable branch),
        # then bisect: the tip may be pinned between nodes (lattice trapping), so a(delta)
        # is a staircase and a0 is reached to within the step it jumps over
        f = el.radius(h) - a0
        slope = 2.0 * a0 - 1.0 / math.sqrt(2.0 * a0)     # JKR d delta / d a
        step = -math.copysign(min(max(2.0 * abs(f) * slope, 1e-3 * el.h0), 0.2 * el.h0), f)
        lo = hi = None
        d_far, h_far = d, h
        for _ in range(60):
            if f == 0.0:
                return h, float(d)
            d_new = d_far + step
            f_new, h_new = radius_at(d_new, h_far, d_far)
            if f_new is None:           # Newton failed: a smaller step
                step *= 0.5
                continue
            if (f_new > 0) != (f > 0):
                lo, hi = sorted([(d_far, h_far), (d_new, h_new)], key=lambda x: x[0])
                break
            d_far, h_far, f = d_new, h_new, f_new
            step = math.copysign(min(2.0 * abs(step), 0.2 * el.h0), step)
        if lo is None:
            raise RuntimeError(f"could not bracket the indentation of a0 = {a0:g} on the window "
                               f"mesh (another band_resolution may start it: 16, the balanced "
                               f"preset, where the fast preset's 9 fails at mu 8-12; model "
                               f"auto answers with the crack-front model)")
        for _ in range(60):
            if best[0] <= 1e-10 * a0 or hi[0] - lo[0] <= 1e-14 * max(1.0, abs(d)):
                break
            d_mid = 0.5 * (lo[0] + hi[0])
            f_mid, h_mid = radius_at(d_mid, lo[1], lo[0])
            if f_mid is None:
                break
            if f_mid > 0:
                hi = (d_mid, h_mid)
            else:
                lo = (d_mid, h_mid)
        if best[0] <= 2.0 * spacing:
            return best[1], float(best[2])
        raise RuntimeError(f"the tip jumps over a0 = {a0:g} by more than two fine spacings "
                           f"(closest {best[0]:.3g} a_ref away): refine the mesh")
    return relaxed_state(el, delta0=scene.delta0, a0=scene.a0)


#: a0 (a_ref) from which the initial state on the window mesh may be solved directly: twice
#: the JKR fold radius 1/2, far above the fold of the relaxed branch at any mu
DIRECT_INITIAL_A0 = 1.0


def direct_initial_state(el: ElasticSolver, pb, scene: Scene):
    """The relaxed state solved directly on the window mesh of ``pb``, as the graded mesh
    solves it (:func:`sweep.engine.initial.relaxed_state`, cached per process alike):
    (gap, indentation), or None where that is not to be trusted or not cheap, and the
    quasi-static branch (:func:`branch_state`) gives the state instead:

    - a0 below :data:`DIRECT_INITIAL_A0`;
    - a scene whose graded band would not fit ``max_nodes`` (a large Tabor parameter): there
      the LJ stiffness makes the direct solves ill-conditioned, Newton can settle with the
      tip on the coarse mesh outside the window, and the continuation that follows costs a
      dense factorization per solve (mu = 30, a0 = 1.5, balanced: 99 s, then no state);
    - no converged state, or one whose tip is not within two fine spacings of a0 inside the
      window.
    """
    numerics, s = pb.numerics, pb.scales
    if scene.a0 is None or scene.a0 < DIRECT_INITIAL_A0:
        return None
    if band_nodes(numerics, s.tip_zone, s.a0_estimate, s.domain,
                  pull_off_only=scene.stop == "pulloff") > numerics.max_nodes:
        return None
    try:
        h, d = relaxed_state(el, a0=scene.a0, mesh_key=(pb.mesh.key, pb.mesh.spacing))
    except OverBudget:
        raise
    except RuntimeError:
        return None
    finally:
        invalidate(el.cache)    # the unloading starts unfactorized, cached state or not
    a = el.radius(h)
    lo, hi = pb.tip_range
    if not (lo <= a <= hi and abs(a - scene.a0) <= 2.0 * pb.mesh.spacing):
        return None
    return h, d


def _probe(scene, numerics, run, delta0, a0, per_step, margin, deadline) -> str:
    """After a chunk of a run (the probe of PROBE_STEPS steps, then each chunk of at least
    as many; ``per_step`` its wall time per step): the reason to end the run now when the
    least number of steps it still needs (:func:`estimate_steps`, with indentation steps
    growing from the largest so far) exceeds max_steps or, at ``per_step``, takes more than
    ``margin`` times the time left before ``deadline``; else ""."""
    n = run.n
    delta, a = run.records[1][:n], run.records[3][:n]
    if n < 3:
        return ""
    step = float(np.max(-np.diff(delta)))
    if run.step.size > 2 and run.step[2] > 0.0:
        # a protocol's retraction in its lead-in (kernels.solve.LEAD_GROWTH): its steps grow
        # to numerics.step and on as the step control lets them, as the estimate before the
        # run assumes (_attempt); a fast approach's last step had made the retraction's first
        # steps 1e-5 of numerics.step, and "too many steps" of a scene that then took 2768
        step = max(step, SMOOTH_STEP_FACTOR * numerics.step * derive(scene, numerics).h0)
    need = estimate_steps(scene, numerics, delta[-1], a[-1], delta0, a0, step)
    total = n - 1 + need.steps
    if total > numerics.max_steps:
        return (f"too many steps: {need.describe()}, as the first {n - 1} steps took: about "
                f"{total} steps > max_steps = {numerics.max_steps}; raise max_steps, or lower "
                f"band_resolution{crack_front_advice(scene)}")
    left = deadline - time.perf_counter()
    if need.steps * per_step > margin * left:
        return (f"time budget: needs at least {total} steps ({need.describe()}, as the first "
                f"{n - 1} steps took) at {1e3 * per_step:.2g} ms per step on {run.h.size} "
                f"nodes: about {need.steps * per_step:.2g} s more, > {margin:g} x the "
                f"{max(left, 0.0):.2g} s left of time_budget_s = {numerics.time_budget_s:g}; raise "
                f"time_budget_s, or lower band_resolution{crack_front_advice(scene)}")
    return ""


def simulate_tip_following(scene: Scene, numerics: Numerics | None = None,
                           ahead: float = WINDOW_AHEAD_ZONES,
                           behind: float = WINDOW_BEHIND_ZONES) -> Result:
    """Simulate one scene with the BEM on a mesh refined around the moving crack tip.

    Parameters
    ----------
    scene : Scene
    numerics : Numerics, optional
        Default ``Numerics.preset("balanced")``; the fine spacing is the tip zone / band_resolution
        (or, with ``nodes`` set, the mesh of that many nodes), the rest as for
        :func:`sweep.engine.bem.simulate` (steps, tolerances, time budget, error estimate).
    ahead, behind : float
        The window, in tip zones (see :func:`tip_window`).

    Returns
    -------
    Result
        As :func:`sweep.engine.bem.simulate`; ``nodes_used`` is the largest mesh of the run,
        ``reason`` of an ok result says how many meshes it took.
    """
    numerics = Numerics.preset("balanced") if numerics is None else numerics
    attempt = _attempt if scene.protocol() is None else _attempt_protocol
    t_start = time.perf_counter()
    with budget.scene_budget(numerics.time_budget_s) as deadline:
        res = attempt(scene, numerics, ahead, behind, deadline)
        estimate_error(res, derive(scene, numerics).tip_zone,
                       lambda coarse: attempt(scene, coarse, ahead, behind, deadline))
    res.wall_s = time.perf_counter() - t_start
    return res


def _attempt(scene, numerics, ahead, behind, deadline) -> Result:
    if numerics.mesh != "graded" or numerics.exact:
        numerics = dataclasses.replace(numerics, mesh="graded", exact=False)
    res = Result(scene=scene, numerics=numerics)
    scales = derive(scene, numerics)
    zone = scales.tip_zone
    d_est, a_est, domain = scales.delta0_estimate, scales.a0_estimate, scales.domain
    # up front: the least steps of the run, with every step as large as the kernel's step
    # control ever lets it grow
    need = estimate_steps(scene, numerics, d_est, a_est, d_est, a_est,
                          SMOOTH_STEP_FACTOR * numerics.step * scales.h0)
    if need.steps > numerics.max_steps:
        res.reason = (f"too many steps: {need.describe()}: > {need.steps} steps (max_steps = "
                      f"{numerics.max_steps}); raise max_steps, or lower band_resolution"
                      f"{crack_front_advice(scene)}")
        return res
    try:
        branch, from_branch = None, False

        def branch_start():
            nonlocal branch
            if branch is None and scene.a0 is not None:
                branch = branch_state(scene, numerics.band_resolution, domain)
            try:
                return initial_state(el, scene, branch)
            finally:
                invalidate(el.cache)    # the unloading starts unfactorized, cached or not

        # the initial state: where the relaxed tip lies outside the first window (delta0
        # scenes, whose radius is a JKR estimate), once more with the window there
        for _ in range(2):
            pb = window_problem(scene, numerics, a_est, zone, ahead, behind)
            el = ElasticSolver(pb.A, pb.mesh.r, pb.h0, pb.c, numerics.tol)
            direct = direct_initial_state(el, pb, scene) if not from_branch else None
            if direct is not None:
                h_init, delta0 = direct
            else:
                # the branch and its polish depend on the window mesh, mu and a0 (or
                # delta0) only: once per process for a sweep over materials and rates
                from_branch = True
                h_init, delta0 = cached_state(
                    ("branch", pb.mesh.key, pb.mesh.spacing, el.h0, el.c, el.tol, scene.a0,
                     scene.delta0, numerics.band_resolution, domain), branch_start, el.stats)
            a_init = el.radius(h_init)
            lo, hi = pb.tip_range
            if lo <= a_init <= hi or a_init <= 0.0:
                break
            a_est = a_init
    except (Refused, OverBudget) as exc:
        res.reason = str(exc)
        return res
    except RuntimeError as exc:
        res.reason = f"initial state: {exc}"
        return res
    res.delta0_result, res.a0_result = delta0, a_init
    res.a0_inner = el.radius(h_init, 1.0)
    res.spacing, res.domain_used = pb.mesh.spacing, pb.mesh.domain
    res.prony_terms, res.prony_error = int(pb.prony_weights.size), pb.prony_error
    if a_init <= 0.0:
        res.reason = no_contact_reason(scene, a_init)
        return res
    if a_init >= pb.mesh.r[-2]:
        res.reason = f"initial contact radius {a_init:.4g} reaches the mesh edge"
        return res

    run = UnloadingState.start(pb, h_init, delta0, el.cache, el.stats.copy())
    u = _unload_following(scene, numerics, pb, run, zone, ahead, behind, deadline, delta0,
                          a_init)
    if u.ended in ("probe", "remesh"):
        res.reason = u.reason
        if u.ended == "probe":
            res.steps, res.nodes_used = run.n - 1, u.nodes
            res.newton_iterations = int(run.stats[STAT_ITER])
            res.factorizations = int(run.stats[STAT_FACTOR])
        return res
    n = run.n
    t, delta, P, a, a_inner = (x[:n].copy() for x in run.records)
    res.trajectory = {"t": t, "delta": delta, "P": P, "a": a, "a_inner": a_inner}
    res.steps = n - 1
    res.newton_iterations = int(run.stats[STAT_ITER])
    res.factorizations = int(run.stats[STAT_FACTOR])
    res.nodes_used = u.nodes
    return _finish_following(res, u, scales, u.meshes, u.nodes, u.marks)


def _finish_following(res, u, scales, meshes, nodes, remeshed, first=0) -> Result:
    """The row of a run on the tip-following mesh whose trajectory ``res`` holds, from how
    its unloading ended (``u``, :class:`_Unloaded`): a broken re-meshing's or the mesh
    count's reason, else :func:`finish` on the last mesh (records from ``first`` on, the
    first record of each new mesh in ``remeshed``), the Prony window checked, and the meshes
    it took in the reason."""
    if u.ended == "broken":
        res.reason = u.reason
        return res
    if u.status == STATUS_LEFT_BAND:
        res.reason = f"more than {MAX_MESHES} meshes (a = {res.trajectory['a'][-1]:.4g})"
        return res
    spacing = u.pb.mesh.spacing
    finish(res, u.status, res.trajectory, spacing, STOP_TRAVEL_SPACINGS * spacing, scales,
           advice=fold_advice(res.scene), remeshed=remeshed, first=first)
    check_prony_window(u.pb, res)
    if res.ok:
        note = f"tip-following mesh: {meshes} meshes of at most {nodes} nodes"
        res.reason = f"{res.reason}; {note}" if res.reason else note
    return res


class MarchWindow:
    """The march of a test protocol (approach and dwell, :mod:`sweep.engine.protocol`) on
    the tip-following mesh. Called with the march before each chunk of its steps
    (:meth:`sweep.engine.protocol._March.follow_tip`), it bounds the chunk so that the crack
    tip, which a step moves by at most MARCH_TIP_STEP ``da_max`` spacings, stays inside the
    window's fine range (``pb.tip_range``); where the tip lies within two such steps of the
    range's end, the window is moved to the tip (``ahead`` tip zones of room in the direction
    the tip moves: outward while the contact grows) and the march's state carried there
    (:func:`transfer`, as the unloading's: the gap, and the Prony modes as displacements,
    re-equilibrated at frozen time), and the march goes on
    (:meth:`sweep.engine.protocol._March.move_to`)."""

    def __init__(self, scene, numerics, zone, ahead, behind):
        self.scene, self.numerics, self.zone = scene, numerics, zone
        self.ahead, self.behind = ahead, behind
        self.meshes, self.nodes = 1, 0

    def __call__(self, m) -> None:
        a = m.records["a"]
        self.nodes = max(self.nodes, m.pb.mesh.nodes)
        move = MARCH_TIP_STEP * self.numerics.da_max * m.pb.mesh.spacing
        lo, hi = m.pb.tip_range
        room = min(hi - a[-1], a[-1] - lo)
        if room < 2.0 * move:
            direction = -1 if len(a) > 1 and a[-1] < a[-2] else 1
            budget.check(f"the tip-following mesh's re-meshing at a = {a[-1]:.4g}")
            new = window_problem(self.scene, self.numerics, a[-1], self.zone, self.ahead,
                                 self.behind, direction)
            # the march's state as an unloading's run: with a process zone, its last step's
            # law (the state before it, that step's length) carried too
            run = types.SimpleNamespace(h=m.h, q=m.q, sigma=m.sigma, h_prev=m.h_prev, n=len(a),
                                        records=[None, m.records["delta"]],
                                        step=np.array([0.0, m.dt_prev, 0.0]), stats=m.stats,
                                        cache=None)
            transfer(run, m.pb, new)
            m.move_to(new, run.h, run.q, run.sigma)
            self.meshes, self.nodes = self.meshes + 1, max(self.nodes, new.mesh.nodes)
            lo, hi = new.tip_range
            room = min(hi - a[-1], a[-1] - lo)
        m.chunk_steps = int(min(DWELL_CHUNK_STEPS, max(1.0, room // move - 1.0)))


def _attempt_protocol(scene, numerics, ahead, behind, deadline) -> Result:
    """One solve of a scene with a test protocol on the tip-following mesh: the march
    (approach and dwell, :func:`sweep.engine.protocol.run_phases`) from first contact on a
    window that follows the growing contact (:class:`MarchWindow`), then the retraction
    from the march's last state as an unloading on windows that follow the crack tip
    (:func:`_unload_following`). The row is the graded mesh's protocol row
    (:func:`sweep.engine.bem._simulate_protocol`): the pull-off read on the retraction,
    the trajectory's phases, the hysteresis energy."""
    if numerics.mesh != "graded" or numerics.exact:
        numerics = dataclasses.replace(numerics, mesh="graded", exact=False)
    res = Result(scene=scene, numerics=numerics)
    scales = derive(scene, numerics)
    zone = scales.tip_zone
    window = MarchWindow(scene, numerics, zone, ahead, behind)
    stats = np.zeros(N_STATS, dtype=np.int64)
    try:
        pb = window_problem(scene, numerics, first_contact_radius(scene), zone, ahead,
                            behind, 1)
        march = run_phases(pb, scene.protocol(), stats, follow=window)
    except (Refused, OverBudget) as exc:
        res.reason = str(exc)
        return res
    except RuntimeError as exc:
        res.reason = f"protocol: {exc}"
        return res
    pb, rec = march.pb, march.records
    n0 = len(rec["t"])
    res.delta0_result, res.a0_result, res.a0_inner = march.delta, rec["a"][-1], rec["a_inner"][-1]
    res.spacing, res.domain_used = pb.mesh.spacing, pb.mesh.domain
    res.prony_terms, res.prony_error = int(pb.prony_weights.size), pb.prony_error
    run = retraction_start(pb, march, stats)
    u = _unload_following(scene, numerics, pb, run, zone, ahead, behind, deadline,
                          march.delta, rec["a"][-1])
    meshes, nodes = window.meshes + u.meshes - 1, max(window.nodes, u.nodes)
    res.nodes_used = nodes
    res.steps = n0 - 1 + run.n - 1
    res.newton_iterations, res.factorizations = int(stats[STAT_ITER]), int(stats[STAT_FACTOR])
    if u.ended in ("probe", "remesh"):
        res.reason = u.reason
        return res
    join_phases(res, march, run)
    first = n0 - 1
    return _finish_following(res, u, scales, meshes, nodes,
                             [first] + [first + i for i in u.marks], first=first)


@dataclasses.dataclass
class _Unloaded:
    """How an unloading on the tip-following mesh ended (:func:`_unload_following`): the
    kernel's last status, the last mesh's problem, the meshes, the most nodes of one, the
    first record on each new mesh; ``ended`` "probe" (a refusal of :func:`_probe`),
    "remesh" (a re-meshing failed) or "broken" (a re-meshing broke the load's continuity,
    :func:`_continuity`) with its ``reason``, else ""."""
    status: int
    pb: object
    meshes: int
    nodes: int
    marks: list
    ended: str = ""
    reason: str = ""


def _unload_following(scene, numerics, pb, run, zone, ahead, behind, deadline, delta0,
                      a0) -> _Unloaded:
    """Continue the unloading ``run`` from the window mesh of ``pb`` to its end: the kernel in
    chunks (:func:`sweep.engine.bem.unload_chunk`), the window moved to the crack tip where
    the tip leaves it (:func:`transfer`), each re-meshing's load continuity checked, the run
    probed for what it still needs (:func:`_probe`, from the start at ``delta0``, ``a0``)."""
    u = _Unloaded(STATUS_STEP_LIMIT, pb, 1, pb.mesh.nodes, [])
    remeshed_at = []    # first records on new meshes, to check (u.marks: all of them)
    rtol = max(REMESH_JUMP_RTOL, 0.25 * numerics.pull_off_rtol)
    start = int(run.stats[STAT_FACTOR])
    while True:
        probing, n_before, t_chunk = run.n <= 1, run.n, time.perf_counter()
        u.status = unload_chunk(u.pb, run, u.pb.tip_range,
                                PROBE_STEPS if probing else CHUNK_STEPS, deadline)
        budget.check_work(int(run.stats[STAT_FACTOR]) - start, "the unloading")
        broken = _continuity(scene, run, remeshed_at, rtol)
        if broken:
            u.ended, u.reason = "broken", broken
            return u
        if (u.status in (STATUS_LEFT_BAND, STATUS_STEP_LIMIT)
                and (probing or run.n - n_before >= PROBE_STEPS)):
            per_step = (time.perf_counter() - t_chunk) / max(run.n - n_before, 1)
            refusal = _probe(scene, numerics, run, delta0, a0, per_step,
                             TIME_MARGIN if probing else 1.0, deadline)
            if refusal:
                u.ended, u.reason = "probe", refusal
                return u
        if u.status == STATUS_LEFT_BAND and u.meshes < MAX_MESHES:
            a = run.records[3]
            direction = -1 if a[run.n - 1] < a[max(run.n - 2, 0)] else 1
            try:
                budget.check(f"the tip-following mesh's re-meshing at a = {a[run.n - 1]:.4g}")
                new = window_problem(scene, numerics, a[run.n - 1], zone, ahead, behind,
                                     direction)
                transfer(run, u.pb, new)
            except (Refused, OverBudget) as exc:
                u.ended, u.reason = "remesh", f"re-meshing at a = {a[run.n - 1]:.4g}: {exc}"
                return u
            remeshed_at.append(run.n)
            u.marks.append(run.n)
            u.pb, u.meshes, u.nodes = new, u.meshes + 1, max(u.nodes, new.mesh.nodes)
        elif u.status == STATUS_STEP_LIMIT and run.n <= numerics.max_steps:
            pass
        else:
            return u
        if time.perf_counter() > deadline:
            u.status = STATUS_TIME_BUDGET
            return u


#: the convergence study (``python -m sweep.engine.tip_following``): a viscoelastic scene unloaded
#: from a0 = 1.2 (n = 0.8, k = 0.5, rate 1), fine spacing l0/band_resolution, window
#: (ahead, behind) in l0
STUDY_SCENE = dict(n=0.8, k=0.5, a0=1.2, rate=1.0)
STUDY_RESOLUTIONS = (8.0, 16.0, 24.0)
STUDY_WINDOWS = ((16.0, 8.0), (8.0, 4.0), (32.0, 16.0))


def convergence_study(mu: float, resolutions=STUDY_RESOLUTIONS, windows=STUDY_WINDOWS,
                      preset: str = "balanced", on_row=None, **scene) -> list[dict]:
    """Pull-off of one scene against the fine spacing (at the first window) and the window
    (at the middle resolution). Rows: band_resolution, ahead, behind, status, pull_off,
    nodes, meshes (from the reason), steps, seconds; ``on_row(row)`` as each is done."""
    sc = Scene(mu=mu, **{**STUDY_SCENE, **scene})
    grid = [(res, *windows[0]) for res in resolutions]
    mid = resolutions[len(resolutions) // 2]
    grid += [(mid, *w) for w in windows[1:]]
    rows = []
    for res_, ahead, behind in grid:
        num = Numerics.preset(preset, band_resolution=res_, pull_off_rtol=0.0,
                              time_budget_s=1800.0)
        r = simulate_tip_following(sc, num, ahead, behind)
        meshes = int(r.reason.split(" meshes")[0].split()[-1]) if "meshes" in r.reason else 0
        rows.append(dict(mu=mu, band_resolution=res_, ahead=ahead, behind=behind,
                         status=r.status, pull_off=r.pull_off, nodes=r.nodes_used,
                         meshes=meshes, steps=r.steps, seconds=r.wall_s))
        if on_row is not None:
            on_row(rows[-1])
    return rows


def interpolate_as_traction(run, old, new) -> None:
    """The state transfer before the modes were carried as displacements (for comparison
    only): the gap and each Prony mode interpolated by a cubic spline, no re-equilibration."""
    run.h = np.maximum(CubicSpline(old.mesh.r, run.h)(new.mesh.r), 0.5 * float(np.min(run.h)))
    run.q = np.ascontiguousarray(CubicSpline(old.mesh.r, run.q, axis=1)(new.mesh.r))
    run.cache = new_jacobian_cache(new.mesh.nodes)
    run.sigma = None


def remesh_jumps(scene: Scene, numerics: Numerics | None = None, form: str = "auto",
                 ahead: float = WINDOW_AHEAD_ZONES, behind: float = WINDOW_BEHIND_ZONES):
    """Run a scene and measure the load at each re-meshing up to the pull-off: (result,
    rows of (record m, contact radius, P before, |jump|, the larger change over the
    neighbouring steps)). ``form``: that of :func:`transfer`, or "traction"
    (:func:`interpolate_as_traction`)."""
    global transfer
    marks, carry = [], transfer

    def recording(run, old, new):
        marks.append(run.n)
        if form == "traction":
            interpolate_as_traction(run, old, new)
        else:
            carry(run, old, new, form=form)

    transfer = recording
    try:
        res = simulate_tip_following(scene, numerics, ahead, behind)
    finally:
        transfer = carry
    rows = []
    if res.trajectory:
        P, a = res.trajectory["P"], res.trajectory["a"]
        i_min = int(np.argmin(P))
        for m in marks:
            if 2 <= m < P.size - 1 and m <= i_min + 1:
                rows.append((m, float(a[m - 1]), float(P[m - 1]), float(abs(P[m] - P[m - 1])),
                             float(max(abs(P[m - 1] - P[m - 2]), abs(P[m + 1] - P[m])))))
    return res, rows


def _main(argv=None) -> None:
    import argparse

    p = argparse.ArgumentParser(prog="python -m sweep.engine.tip_following",
                                description="convergence of the tip-following BEM")
    p.add_argument("--mu", type=float, nargs="+", default=[30.0, 100.0])
    p.add_argument("--resolutions", type=float, nargs="+", default=list(STUDY_RESOLUTIONS))
    for name in ("n", "k", "a0", "rate"):
        p.add_argument(f"--{name}", type=float, default=STUDY_SCENE[name],
                       help=f"the scene's {name} (default {STUDY_SCENE[name]:g})")
    p.add_argument("--jumps", choices=("auto", "relaxed", "glassy", "traction"),
                   help="instead of the study: the load at each re-meshing up to the "
                        "pull-off with this state transfer (traction: the modes interpolated "
                        "as tractions, as before the fix)")
    args = p.parse_args(argv)
    scene = {name: getattr(args, name) for name in STUDY_SCENE}
    if args.jumps:
        for mu in args.mu:
            t0 = time.perf_counter()
            res, rows = remesh_jumps(Scene(mu=mu, **scene), form=args.jumps)
            print(f"mu {mu:g} {scene} transfer {args.jumps}: {res.status} pull-off "
                  f"{res.pull_off:.6g}, {res.steps} steps, {res.nodes_used} nodes, "
                  f"{time.perf_counter() - t0:.0f} s; {res.reason}")
            for m, a, P, jump, typical in rows:
                print(f"  re-meshing at a = {a:.4f}: P = {P:.5f}, jump {jump:.3g} = "
                      f"{jump / abs(P):.2e} |P|, beyond the neighbouring steps' "
                      f"{max(jump - typical, 0.0) / abs(P):.2e} |P|")
        return
    print(f"scene {scene}, preset balanced; windows (ahead, behind) in l0")
    print(f"{'mu':>5} {'res':>4} {'ahead':>5} {'behind':>6} {'status':>6} {'pull_off':>9} "
          f"{'nodes':>5} {'meshes':>6} {'steps':>6} {'s':>6}")

    def show(r):
        print(f"{r['mu']:5g} {r['band_resolution']:4g} {r['ahead']:5g} {r['behind']:6g} "
              f"{r['status']:>6} {r['pull_off']:9.5f} {r['nodes']:5d} {r['meshes']:6d} "
              f"{r['steps']:6d} {r['seconds']:6.1f}", flush=True)

    for mu in args.mu:
        convergence_study(mu, tuple(args.resolutions), on_row=show, **scene)


if __name__ == "__main__":
    _main()
