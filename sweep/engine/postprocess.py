"""A computed unloading turned into a result: the refined load minimum, the state and the
crack speed there (:func:`finish`, shared by every BEM mesh)."""
from __future__ import annotations

import math
from contextlib import contextmanager

import numpy as np

# STATUS_TIME_BUDGET: a run stopped by ``Numerics.time_budget_s``, between kernel calls or by
# the kernel itself (its deadline, kernels.jacobian.set_deadline)
from ..kernels.solve import (STATUS_DOMAIN, STATUS_NEWTON_FAILED, STATUS_STEP_LIMIT,
                             STATUS_TIME_BUDGET, stop_reached)

#: a compliant machine (stiffness K) holds the sphere while dP/ddelta > -K: past the load
#: minimum the load rises until the slope reaches -K, where the sphere jumps off (the
#: machine's fold, no equilibrium nearby). A run whose solve fails after the minimum with
#: the last records' slope below this fraction of -K has reached that fold: its pull-off is
#: the minimum (measured on n 0.5, k 1, mu 3.24, a0 2: -0.06 and -0.19 at K = 0.1 and 0.3)
MACHINE_FOLD_FRACTION = 0.5


def machine_fold(P, delta, i_min: int, stiffness) -> float:
    """The slope dP/ddelta (pi dg R/d_ref) of the last two records where they lie past the
    load minimum ``i_min`` with the load risen, a compliant machine's (``stiffness`` K) run
    ending there at its fold (:data:`MACHINE_FOLD_FRACTION`); nan otherwise (or for a rigid
    machine, ``stiffness`` None)."""
    n = len(P)
    if stiffness is None or n - 1 - i_min < 2 or not P[-1] > P[i_min] or delta[-1] == delta[-2]:
        return math.nan
    slope = float((P[-1] - P[-2]) / (delta[-1] - delta[-2]))
    return slope if slope <= -MACHINE_FOLD_FRACTION * stiffness else math.nan


def folded_past_minimum(P, a, i_min: int, min_travel: float) -> bool:
    """Whether a run whose discrete path folded (no equilibrium at its smallest step) had
    passed its load minimum ``i_min`` (tensile) before: the crack tip receded by
    ``min_travel`` (a_ref) since, the stop rule's guard against a dip of the load as the tip
    crosses a node, with the load above the minimum at the fold. The stop rule's recovery
    of RECOVERY |P_min| (:func:`sweep.kernels.solve.stop_reached`) keeps a run going that
    can; a folded one cannot, and its minimum is the pull-off. Measured on the folded
    protocols of the random samples (a protocol has no other model to answer it): at mu
    18.33 the minima at band resolutions 9, 16 and 24 (folds 4.8-55 spacings past them)
    were 6.4e-4, 3.4e-5 and 8.5e-5 from the accurate preset's ok row; with a process zone
    at n 0.627, 147.77 / 147.46 / 146.92 at 16 / 24 / 36, converging."""
    n = len(P)
    return bool(P[i_min] < 0.0 and n - 1 > i_min and P[n - 1] > P[i_min]
                and a[i_min] - a[n - 1] >= min_travel)


#: a parabola refinement lowering the sampled minimum by more than this fraction must
#: also predict the neighbouring samples (see :func:`refine_minimum`)
VERTEX_RTOL = 1e-3
#: how the reason of a row whose unloading found no equilibrium at its smallest step before
#: the pull-off begins (the discrete path folds; an accuracy request refines it once,
#: ``sweep.engine.models``)
FOLD_REASON = "no equilibrium found at the minimum step before pull-off"


#: what a row whose load overflowed advises: its time steps grew past what the solve's
#: arithmetic holds (rates below about 1e-100 at the balanced preset: steps of 1e103 tau0 and
#: more), far past the relaxed limit (`sweep scene --a0 2 --rate 1e-90` and `1e-100` give the
#: same pull-off, 1.5459365576, to 1e-12)
OVERFLOW_ADVICE = ("A slower unloading than the material's longest retardation time is its "
                   "relaxed limit: a larger rate gives the same pull-off")


#: a test protocol's records keep the absolute time. Where its float spacing at the
#: retraction's start exceeds this fraction of the retraction's mean step, the pull-off's
#: instant and the crack speed are read on the retraction's own clock, from its indentation
#: (:func:`retraction_clock`): after a dwell of 1e13 tau0 the crack speed at a retraction at
#: rate 10 read 0.840 on the absolute clock, 0.630 after 1e14, and a dwell of 1e15 failed the
#: row (its fit's times all equal), where shorter dwells converge to 0.7879
CLOCK_RESOLUTION = 1e-4


def retraction_clock(t, delta, first: int, loading_speed: float):
    """(the records' times, the offset to add back): ``t`` itself with offset 0, or where a
    test protocol's absolute clock no longer resolves its retraction's steps
    (:data:`CLOCK_RESOLUTION`), the time since the retraction's start, from the retraction's
    records on as (delta[first] - delta) / ``loading_speed`` (a rigid machine lowers the
    indentation at that constant speed, d_ref/tau0), with offset t[first]."""
    n = len(t)
    if first <= 0 or n - first < 2:
        return t, 0.0
    mean_step = (t[-1] - t[first]) / (n - 1 - first)
    if np.spacing(t[first]) <= CLOCK_RESOLUTION * mean_step:
        return t, 0.0
    local = np.asarray(t, float) - t[first]
    local[first:] = (delta[first] - np.asarray(delta[first:], float)) / loading_speed
    return local, float(t[first])


def machine_clock(t, delta, a, t_star: float, lo: int, hi: int, spacing: float,
                  loading_speed: float, stiffness=None, window_nodes=3.0, min_points=5):
    """(clock, its value at ``t_star``): the clock on which the crack-speed fit reads da/dt
    at the load minimum. ``t`` itself for a rigid machine. A compliant machine (stiffness K)
    moves the sphere at its own speed only where the load is stationary, d delta/dt =
    dD/dt - (dP/dt)/K: near the minimum the sphere's speed runs from about half to three
    times the machine's on a soft spring (K 0.03, an elastic sphere at mu 5), and a quadratic
    a(t) fit there read the crack speed 14 % high (5 % at K 0.3; a user test of session 51,
    against rate h0 da/ddelta and the rigid machine's, which an elastic sphere's must equal).
    The indentation's own clock, (delta[lo] - delta)/``loading_speed``, runs at the machine's
    rate at the minimum (dP/dt = 0 there), so that a fit on it reads da/dt there; it is used
    where the indentation falls monotonically over the records ``lo:hi`` that the fit may
    take (``window_nodes`` spacings of the radius at ``t_star``, as :func:`crack_speed_at`),
    else ``t`` (a minimum at a jump of the sphere)."""
    if stiffness is None or not math.isfinite(stiffness) or hi - lo < 3:
        return t, t_star
    seg_t = np.asarray(t[lo:hi], float)
    d, r = np.asarray(delta[lo:hi], float), np.asarray(a[lo:hi], float)
    near = np.flatnonzero(np.abs(r - np.interp(t_star, seg_t, r)) <= window_nodes * spacing)
    near = np.union1d(near, np.argsort(np.abs(seg_t - t_star))[:min_points])
    span = slice(int(near.min()), int(near.max()) + 1)
    if not np.all(np.diff(d[span]) < 0.0):
        return t, t_star
    clock = np.array(t, float)
    clock[lo:hi] = seg_t[0] + (d[0] - d) / loading_speed
    return clock, float(np.interp(t_star, seg_t, clock[lo:hi]))


def stop_mode(scene) -> int:
    """The stop rule's mode of ``scene`` (:func:`sweep.kernels.solve.stop_reached`): 1
    following the curve to separation; 2 stopping after the pull-off with a process zone,
    which may hold the surfaces after the contact's end while the load still falls; else 0,
    stopping after the pull-off."""
    if scene.stop != "pulloff":
        return 1
    return 2 if scene.pz_law != "none" else 0


#: where :func:`capture_fits` collects the crack-speed fits' inputs (None: not collecting)
_FIT_LOG: list | None = None


@contextmanager
def capture_fits():
    """Collect, in the yielded list, the inputs of every crack-speed fit :func:`finish`
    makes in this process while the block runs: a dict per fit with the records ``t``,
    ``a``, the pull-off instant ``t_star``, the fine ``spacing`` and the span ``lo:hi`` of
    records computed on the minimum's mesh (the arguments of :func:`crack_speed_on_mesh`).
    A diagnostic for studies of the fit (``python -m sweep.bench.crack_speed``)."""
    global _FIT_LOG
    outer, _FIT_LOG = _FIT_LOG, []
    try:
        yield _FIT_LOG
    finally:
        _FIT_LOG = outer


def refine_minimum(t, P):
    """(t*, P*) of the minimum of P(t) refined by a parabola through the 3 samples around it.

    The parabola is rejected, and the sampled minimum returned, where it is no local model
    of P (a kink or a jump of the load): where it lowers the minimum by more than
    max(P[i-1], P[i+1]) - P[i] (impossible for a parabola through equally spaced samples),
    or by more than VERTEX_RTOL |P[i]| while missing the samples i - 2, i + 2 by more than
    it lowers the minimum.
    """
    i = int(np.argmin(P))
    if 0 < i < len(P) - 1:
        # in time from the middle sample: in absolute time (t* ~ 3600 tau0 after a test
        # protocol's dwell, steps of 1e-4) the parabola's terms cancelled to float32's
        # precision (a pull-off quantized to 4.689464569091797 whatever the approach)
        t0 = t[i]
        tt = np.asarray(t, float) - t0
        x = tt[i - 1:i + 2]
        y = P[i - 1:i + 2]
        denom = (x[0] - x[1]) * (x[0] - x[2]) * (x[1] - x[2])
        if denom != 0:
            A = (x[2] * (y[1] - y[0]) + x[1] * (y[0] - y[2]) + x[0] * (y[2] - y[1])) / denom
            B = (x[2] ** 2 * (y[0] - y[1]) + x[1] ** 2 * (y[2] - y[0]) + x[0] ** 2 * (y[1] - y[2])) / denom
            C = y[1] - A * x[1] ** 2 - B * x[1]
            if A > 0:
                ts = -B / (2 * A)
                vertex = A * ts * ts + B * ts + C
                miss = 0.0
                for j in (i - 2, i + 2):
                    if 0 <= j < len(P):
                        miss = max(miss, abs(A * tt[j] ** 2 + B * tt[j] + C - P[j]))
                drop = y[1] - vertex
                smooth = (drop <= max(y[0], y[2]) - y[1]
                          and (drop <= VERTEX_RTOL * abs(y[1]) or miss <= drop))
                if x[0] <= ts <= x[2] and smooth:
                    return i, t0 + ts, min(vertex, y[1])
    return i, t[i], P[i]


def crack_speed_at(t, a, t_star, spacing, window_nodes=3.0, min_points=5):
    """-da/dt at ``t_star`` from a quadratic least-squares fit of a(t) nearby.

    The fit uses the samples whose radius lies within ``window_nodes`` node spacings of
    a(t_star) (a(t) has kinks where it crosses nodes), widened to at least ``min_points``.
    """
    a_star = np.interp(t_star, t, a)
    sel = np.flatnonzero(np.abs(a - a_star) <= window_nodes * spacing)
    if sel.size < min_points:
        order = np.argsort(np.abs(t - t_star))
        sel = np.sort(order[:min_points])
    if sel.size < 3:
        return math.nan
    tt = t[sel] - t_star
    scale = max(np.max(np.abs(tt)), 1e-300)
    coef = np.polyfit(tt / scale, a[sel], 2)
    return -coef[1] / scale


def crack_speed_on_mesh(t, a, t_star, spacing, lo, hi, window_nodes=3.0, min_points=5):
    """:func:`crack_speed_at` on the records ``lo:hi`` computed on one mesh; where its fit's
    samples reach an end of that span at which the run was re-meshed, the records of the
    neighbouring mesh within the same radius window join the fit, each side with an offset
    of its own (the small step the state transfer makes in the radius), so that the fit is
    not one-sided: at a minimum on the last record of a mesh a one-sided quadratic read the
    crack speed 4 % low (n 0.8, a0 5, rate 1, balanced, window 10/6)."""
    seg_t, seg_a = t[lo:hi], a[lo:hi]
    a_star = np.interp(t_star, seg_t, seg_a)
    win = window_nodes * spacing
    sel = np.flatnonzero(np.abs(seg_a - a_star) <= win)

    def reach(j, step):     # the neighbouring mesh's records within the window, from j on
        out = []
        while 0 <= j < len(t) and abs(a[j] - a_star) <= win:
            out.append(j)
            j += step
        return out

    before = reach(lo - 1, -1) if sel.size and sel[0] == 0 else []
    after = reach(hi, 1) if sel.size and sel[-1] == hi - lo - 1 else []
    if not before and not after:
        return crack_speed_at(seg_t, seg_a, t_star, spacing, window_nodes, min_points)
    idx = np.array(sorted(before) + list(lo + sel) + after)
    tt = t[idx] - t_star
    scale = max(np.max(np.abs(tt)), 1e-300)
    x = tt / scale
    cols = [np.ones_like(x), x, x * x]
    cols += [(idx < lo).astype(float)] if before else []
    cols += [(idx >= hi).astype(float)] if after else []
    X = np.column_stack(cols)
    if idx.size < X.shape[1] + 2:
        return crack_speed_at(seg_t, seg_a, t_star, spacing, window_nodes, min_points)
    coef = np.linalg.lstsq(X, a[idx], rcond=None)[0]
    return -coef[1] / scale


def one_mesh_span(i: int, n: int, remeshed=()) -> tuple[int, int]:
    """The records ``lo:hi`` computed on the same mesh as record ``i`` of ``n``, where
    ``remeshed`` lists the first record of each new mesh (a re-meshing of the tip-following
    mesh lies between records m - 1 and m)."""
    lo = max((int(m) for m in remeshed if m <= i), default=0)
    hi = min((int(m) for m in remeshed if m > i), default=n)
    return lo, hi


def finish(res, status: int, trajectory: dict, spacing: float, min_travel: float, scales,
           advice: str, remeshed=(), machine_stiffness=None, first: int = 0) -> None:
    """Fill ``res`` from a finished unloading, in place: ``ok`` with the pull-off, the state
    and crack speed at the pull-off instant, or a failure with its reason.

    Quantities read at the pull-off instant never straddle a re-meshing: the parabola through
    the samples around the load minimum and the crack-speed fit use only the records computed
    on the mesh of the minimum's record (:func:`one_mesh_span`); the state transfer makes the
    load and the tip radius step a little (within the continuity guard), and a difference
    quotient across such a step is no crack speed. Where the minimum is the first or last
    record of its mesh, the reason says so and how far the load stepped there. Where it is
    the initial state (the contact starts at or beyond its pull-off), the crack speed is the
    first step's radius change over its time, and the reason says so. An ``ok``
    result never has a negative crack speed at pull-off (the contact advancing at the load
    minimum): that is a failure with its reason.

    Parameters
    ----------
    res : sweep.Result
    status : the kernel's status (or STATUS_TIME_BUDGET).
    trajectory : arrays ``t, delta, P, a, a_inner`` of the run (tau0, d_ref, pi dg R, a_ref).
    spacing : the fine node spacing (a_ref), the scale of the crack-speed fit.
    min_travel : crack-tip recession after the load minimum that counts as past the
        pull-off (a_ref, :func:`sweep.kernels.solve.stop_reached`).
    scales : the scene's :class:`sweep.engine.problem.Scales` (process zone for ``vhat``,
        loading speed for ``rhat_pb``).
    advice : what to change when no equilibrium was found before the pull-off (it depends
        on the mesh that ran).
    remeshed : indices of the first record on each new mesh (the tip-following mesh), empty
        for a run on one mesh.
    machine_stiffness : the scene's compliant machine K (pi dg R/d_ref), None for a rigid
        one: a solve failing at its fold after the minimum (:func:`machine_fold`) has passed
        the pull-off.
    first : the unloading's first record (a test protocol's retraction: the records before
        it are the approach's and the dwell's). The pull-off is the load minimum from there
        on: an approach's first contact can pull as hard as the pull-off (a low Tabor
        parameter's, where both are near the DMT value 2).
    """
    t, delta, P, a, a_inner = (trajectory[k] for k in ("t", "delta", "P", "a", "a_inner"))
    overflow = ~np.isfinite(P[first:])
    if overflow.any():
        k = first + int(np.argmax(overflow))
        step = t[k] - t[k - 1] if k > 0 else math.nan
        res.reason = (f"the load is not finite from record {k} on (t = {t[k]:.4g} tau0, steps "
                      f"of {step:.3g} tau0): the solve overflowed. {OVERFLOW_ADVICE}")
        return
    t, clock_offset = retraction_clock(t, delta, first, scales.loading_speed)
    i = first + int(np.argmin(P[first:]))
    lo, hi = one_mesh_span(i, len(P), remeshed)
    i, t_star, P_star = refine_minimum(t[lo:hi], P[lo:hi])
    i += lo
    # past the pull-off by the pull-off rule, a process zone's where it has one (a run that
    # follows the curve to separation may fail after it, as one that stops there)
    zone = stop_mode(res.scene) == 2
    passed = stop_reached(P, a, len(P), i, 2 if zone else 0, min_travel)
    fold = machine_fold(P, delta, i, machine_stiffness) if status == STATUS_NEWTON_FAILED \
        else math.nan
    folded = (status == STATUS_NEWTON_FAILED and not passed and not math.isfinite(fold)
              and folded_past_minimum(P, a, i, min_travel))
    passed = passed or math.isfinite(fold) or folded
    if status == STATUS_TIME_BUDGET:
        num = res.numerics
        coarser = ("fewer nodes" if num.mesh == "uniform" or num.nodes is not None
                   else "lower band_resolution")
        res.reason = (f"time budget: {res.numerics.time_budget_s:g} s spent after {len(t) - 1} "
                      f"steps (a = {a[-1]:.4g}, pull-off not reached); give it more "
                      f"(numerics time_budget_s) or cheaper numerics (preset fast, {coarser})")
        return
    if status == STATUS_DOMAIN:
        res.reason = "contact reached the mesh edge: increase numerics.domain"
        return
    if status == STATUS_STEP_LIMIT and not passed:
        res.reason = f"step limit ({res.numerics.max_steps}) reached before pull-off"
        return
    if status == STATUS_NEWTON_FAILED and not passed:
        if machine_stiffness is not None and len(P) - first <= 1:
            # no step from the start: a spring cannot hold a start whose load falls faster
            # than K per unit indentation, which no mesh changes (a user test of session 51)
            res.reason = (f"{FOLD_REASON} (delta={delta[-1]:.6g}, a={a[-1]:.4g}), at the first "
                          f"step: the compliant machine (K = {machine_stiffness:.4g}) cannot "
                          f"hold a start whose load falls faster than K per unit indentation "
                          f"(dP/ddelta < -K, a contact below its pull-off radius); a stiffer "
                          f"machine or a larger a0 holds it, else {advice}")
            return
        res.reason = (f"{FOLD_REASON} (delta={delta[-1]:.6g}, a={a[-1]:.4g}): the discrete "
                      f"path folds where the crack tip is under-resolved; {advice}")
        return
    if P_star >= 0:
        res.reason = "no tensile load reached"
        return
    span = slice(lo, hi)
    at_start = i == first and hi > first + 1
    if at_start:
        # the contact starts at or beyond its pull-off (e.g. past the JKR fold, a0 >= 1/2 at
        # low mu): the load only rises from the initial state, and a fit centred there is
        # one-sided and as poor as the few records it spans; the first step's radius change
        speed = float((a[i] - a[i + 1]) / (t[i + 1] - t[i]))
    else:
        clock, c_star = machine_clock(t, delta, a, t_star, lo, hi, spacing,
                                      scales.loading_speed, machine_stiffness)
        speed = float(crack_speed_on_mesh(clock, a, c_star, spacing, lo, hi))
        if _FIT_LOG is not None:
            _FIT_LOG.append(dict(t=clock.copy(), a=a.copy(), t_star=float(c_star),
                                 spacing=float(spacing), lo=int(lo), hi=int(hi)))
    a_star = float(np.interp(t_star, t[span], a[span]))
    held = ""
    # the contact gone at the record before the minimum already (a DMT-like contact that
    # vanishes at its pull-off is there up to it)
    gone_before = zone and a_star <= 0.0 and i > first and a[i - 1] <= 0.0
    if (speed <= 0 and a_star <= 0.0) or gone_before:
        # a process zone strong enough to hold the surfaces after the contact's end: the load
        # still falls there, slowly, and the crack speed has no tip to follow (a DMT-like
        # contact that vanishes at its pull-off recedes there: speed > 0)
        gone = float(t[span][np.argmax(a[span] <= 0.0)]) + clock_offset
        held = (f"the contact vanished (a = 0 from t = {gone:.4g} tau0) before the load "
                f"minimum P = {P_star:.6g}: the interface held the surfaces after the contact's "
                f"end")
        if not (passed and zone):
            res.reason = (f"{held}, where the crack speed at the pull-off is not defined and "
                          f"the stop rule does not follow the load")
            return
        speed = math.nan       # no crack tip at the pull-off; the stop rule followed the load
    if speed < 0:
        res.reason = (f"negative crack speed at the pull-off ({speed:.4g} a_ref/tau0, the "
                      f"contact advancing at the load minimum P = {P_star:.6g}, a = "
                      f"{float(np.interp(t_star, t[span], a[span])):.4g}): the state at the "
                      f"pull-off is not resolved (a finer mesh or a smaller step may resolve "
                      f"it)")
        return
    res.status = "ok"
    notes = []
    if at_start:
        notes.append("load minimum at the initial state (the contact starts at or beyond its "
                     "pull-off): crack speed from the first step")
    if held:
        notes.append(f"{held}: no crack speed at the pull-off")
    if status == STATUS_NEWTON_FAILED and math.isfinite(fold):
        notes.append(f"stopped at the compliant machine's jump-off after pull-off (dP/ddelta "
                     f"= {fold:.3g} against -K = {-machine_stiffness:.3g})")
    elif folded:
        notes.append(f"the discrete path folds past the load minimum ({len(P) - 1 - i} records "
                     f"later, the crack tip receded {(a[i] - a[-1]) / spacing:.3g} spacings and "
                     f"the load risen by {(P[-1] - P[i]) / abs(P[i]):.2g} of it): the minimum "
                     f"is the pull-off")
    elif status == STATUS_NEWTON_FAILED:
        notes.append("stopped at the jump-off instability after pull-off")
    edge = [m for m in (lo, hi) if 0 < m < len(P) and i in (m - 1, m)]
    if edge:
        m = edge[0]
        notes.append(f"load minimum at a re-meshing (the load stepped by "
                     f"{abs(P[m] - P[m - 1]) / abs(P_star):.2g} |P| there): pull-off and state "
                     f"read on the {'new' if i == m else 'old'} mesh only")
    if notes:
        res.reason = "; ".join(notes)
    res.pull_off = -P_star
    res.t_pulloff = t_star + clock_offset
    res.delta_pulloff = float(np.interp(t_star, t[span], delta[span]))
    res.a_pulloff = float(np.interp(t_star, t[span], a[span]))
    res.a_inner_pulloff = float(np.interp(t_star, t[span], a_inner[span]))
    res.crack_speed = speed
    res.vhat = res.crack_speed / scales.process_zone
    res.rhat_pb = scales.loading_speed
    if "phase" in trajectory and res.scene.stop == "pulloff":
        # a test protocol's cycle ends at its pull-off: the records past it (the stop rule's
        # recovery, some fine spacings of travel) depend on the mesh, not on the test
        res.hysteresis_energy = cycle_work(trajectory, until=cycle_end(res))


def cycle_end(res):
    """Where a test protocol's cycle ends, for :func:`cycle_work`'s ``until``: its pull-off
    (t, delta, P) where the scene stops there, None (the last record) where it follows the
    curve to separation."""
    if res.scene.stop != "pulloff":
        return None
    return res.t_pulloff, res.delta_pulloff, -res.pull_off


def cycle_work(trajectory: dict, until=None, halved: bool = False) -> float:
    """The work the machine did on the sphere over the recorded path, int P d delta
    (trapezoid; pi dg R d_ref): the energy the approach put in less what the retraction took
    back, i.e. what the cycle dissipated (with the surface energy of the contact left at
    the end, none after separation). ``until`` (t, delta, P): the path ends at that state,
    the records from time t on replaced by it (a pull-off run's: its pull-off, read between
    records). ``halved``: the same rule on every other record of each phase (``phase``; its
    first and last kept), for :func:`work_quadrature_error`."""
    P, d = np.asarray(trajectory["P"], float), np.asarray(trajectory["delta"], float)
    phase = np.asarray(trajectory.get("phase", np.zeros(P.size)), float)
    if until is not None:
        keep = np.asarray(trajectory["t"], float) < until[0]
        P, d = np.append(P[keep], until[2]), np.append(d[keep], until[1])
        phase = np.append(phase[keep], phase[keep][-1] if keep.any() else 0.0)
    if halved:
        first = np.flatnonzero(np.diff(phase, prepend=np.nan, append=np.nan) != 0)
        kept = [np.arange(a, b, 2) for a, b in zip(first[:-1], first[1:])]
        idx = np.unique(np.concatenate(kept + [first[1:] - 1]))
        P, d = P[idx], d[idx]
    return float(np.sum(0.5 * (P[1:] + P[:-1]) * np.diff(d)))


def work_quadrature_error(trajectory: dict, until=None) -> float:
    """The relative change of :func:`cycle_work` on every other record of each phase: how well
    the records resolve the cycle's work (the steps resolve the pull-off; at a low Tabor
    parameter a cycle takes 10-60 of them, and the trapezoid of the work on them was up to
    25 % off a finer run where the pull-off's estimate was 4e-4 to 3e-3: ``make
    hysteresis-coverage``). NaN where the work is 0 or not finite."""
    whole = cycle_work(trajectory, until)
    if not (math.isfinite(whole) and whole != 0.0):
        return math.nan
    return abs(whole - cycle_work(trajectory, until, halved=True)) / abs(whole)
