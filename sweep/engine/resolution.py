"""The error estimate of a BEM result: the pull-off change on a mesh of half the resolution
in space and time plus the Prony fit's error (a result whose estimate exceeds
``numerics.pull_off_rtol`` is not ``ok``).

Used alike by the graded mesh (:mod:`sweep.engine.bem`) and the tip-following mesh
(:mod:`sweep.engine.tip_following`).
"""
from __future__ import annotations

import dataclasses
import math
from typing import Callable

from ..errors import shortened
from ..scene import Numerics, Result
from . import budget
from .postprocess import cycle_end, work_quadrature_error

#: the a-priori resolution error, K (spacing/tip zone)^2 (see :func:`resolution_error`),
#: where the half-resolution check cannot run
RESOLUTION_ERROR_K = 2.5


def refine_advice(numerics: Numerics) -> str:
    """How to refine the BEM mesh that ``numerics`` gives (what a failure message advises):
    the node count of a uniform mesh or of a graded mesh of given nodes, else the band
    resolution of the graded and tip-following meshes (fine spacing l0 / band_resolution)."""
    if numerics.mesh == "uniform":
        return "raise nodes (the uniform spacing is domain / (nodes - 1)) or reduce domain"
    if numerics.nodes is not None:
        return ("raise nodes (the graded mesh's fine spacing follows), or leave nodes unset to "
                "size the mesh from band_resolution")
    return "raise band_resolution (the fine spacing is the tip zone / band_resolution)"


def resolution_error(spacing: float, length: float) -> float:
    """Pull-off error expected from the crack-band resolution: RESOLUTION_ERROR_K
    (spacing/length)^2, with ``spacing`` the fine node spacing and ``length`` the tip zone
    it resolves (both a_ref).

    A bound of the measured convergence: the pull-off error times (tip zone/spacing)^2
    reached 2.2 on the narrow-band, fast scene at mu = 1.58 of
    ``tests/engine/test_resolution.py`` (fast, balanced and accurate presets against a much
    finer run, 2026-11-25); on the reference scenes A, D, F it stays below 0.22.
    """
    return RESOLUTION_ERROR_K * (spacing / length) ** 2


def coarser(numerics: Numerics, factor: float = 2.0) -> Numerics:
    """The numerics of the error estimate's cheaper solve: the resolution divided by
    ``factor`` in space (the band resolution, or the nodes; the largest change of the contact
    radius per step, in spacings, stays, so it grows with them in a_ref) and in time (the
    largest indentation step times ``factor``), no coarse-mesh refusal, no check of its own.

    Where the radius change per step is smaller near the pull-off (``da_max_pulloff``), the
    cheaper solve takes that bound throughout, but never below ``da_max / factor`` spacings
    (its own spacings are ``factor`` times larger, so its radius change per step stays at
    least the finer solve's in a_ref): on the coarse mesh a radius change of a whole fine
    ``da_max`` per step made Newton work twice as hard (a balanced threshold scene at a0 = 6,
    da_max 1: 0.138 s against 0.077 s at 0.6), for no gain in what the estimate sees."""
    step = min(factor * numerics.step, 10.0)
    da = {}
    if numerics.da_max_pulloff is not None and numerics.da_max_pulloff < numerics.da_max:
        da = dict(da_max=max(numerics.da_max_pulloff, numerics.da_max / factor),
                  da_max_pulloff=None)
    if numerics.nodes is not None or numerics.mesh == "uniform":
        return dataclasses.replace(numerics, nodes=max(int(numerics.uniform_nodes / factor), 20),
                                   step=step, zone_nodes=0.0, pull_off_rtol=0.0, **da)
    return dataclasses.replace(numerics,
                               band_resolution=max(numerics.band_resolution / factor, 2.0),
                               step=step, zone_nodes=0.0, pull_off_rtol=0.0, **da)


#: the smallest and largest factor of one refinement (:func:`refined`), and the margin on the
#: factor the estimate asks for (a second-order error falls by the factor squared)
REFINE_FACTORS = (math.sqrt(2.0), 2.0)
REFINE_MARGIN = 1.2


#: the advice of a row whose process zone's smoothed law alone misses pull_off_rtol: no
#: finer mesh answers it (:func:`zone_smoothing_error`)
ZONE_SMOOTHING_ADVICE = ("the BEM smooths the process zone's law below a term of 0.03, which "
                         "no finer mesh changes: the crack-front model (model crack or auto) "
                         "follows it exactly")


def zone_smoothing_error(res: Result) -> float:
    """What the BEM's smoothed process-zone law may miss of a row's pull-off: the
    Gent-Schultz term (v/pz_v0)^pz_xi at the pull-off's crack speed v where it is below
    :data:`kernels.interface.ZONE_SMOOTH_TERM`, else 0 (and 0 without a process zone).

    Below that term the law is a cubic that joins 1 (:func:`kernels.interface.zone_factor`),
    which Newton needs, and the zone's effect is lost from a node opening slower than the
    smoothing rate: the BEM's share of the crack-front model's amplification, which follows
    the law exactly, was 0.86, 0.06, 0.002 and 0 at terms 0.026, 0.008, 0.003 and 0.0008 (an
    elastic bulk, mu 5, a0 1.5, rate 0.1, pz_xi 0.5, pz_v0 10-1e4; at a term of 0.08, 1.0).
    The loss is at most the term: the bound, which no finer mesh changes."""
    scene = res.scene
    if scene.pz_law == "none" or not (math.isfinite(res.crack_speed) and res.crack_speed > 0):
        return 0.0
    from ..kernels.interface import ZONE_SMOOTH_TERM   # lazy: the kernels load numba

    term = (res.crack_speed / scene.pz_v0) ** scene.pz_xi
    return term if term < ZONE_SMOOTH_TERM else 0.0


def unresolved(res: Result) -> bool:
    """Whether ``res`` failed only because its error estimate exceeds ``pull_off_rtol``."""
    return res.status == "failed" and res.reason.startswith("unresolved:")


def refined(numerics: Numerics, res: Result) -> Numerics | None:
    """The numerics of the next solve of the unresolved result ``res`` (solved with
    ``numerics``), or None where nothing is left to refine.

    The estimate's discretization part (the estimate less the Prony error) falls by f^2 when
    the spacing and the indentation step are divided by f (second order; the estimate's own
    pair measures it, first order would only make it conservative): f is
    ``REFINE_MARGIN sqrt(discretization part / its share of the tolerance)``, kept within
    :data:`REFINE_FACTORS`. The band resolution (or the node count of a mesh given by it) is
    multiplied by f and the step divided by it; the Prony tolerance is divided by 10 where
    the Prony error takes half the tolerance or more.
    """
    tol = numerics.pull_off_rtol
    prony = res.prony_error if math.isfinite(res.prony_error) else 0.0
    estimate = res.error_estimate if math.isfinite(res.error_estimate) else math.inf
    disc = max(estimate - prony, 0.0)
    share = tol - min(prony, 0.5 * tol)          # what the discretization may take
    lo, hi = REFINE_FACTORS
    f = min(max(REFINE_MARGIN * math.sqrt(disc / share), lo), hi) if math.isfinite(disc) else hi
    changes = {}
    if prony >= 0.5 * tol and numerics.prony_rtol > 1e-9:
        changes["prony_rtol"] = max(numerics.prony_rtol / 10.0, 1e-9)
    if disc > 0.0:
        step = max(numerics.step / f, numerics.min_step, 1e-4)
        if step < numerics.step:
            changes["step"] = step
        if numerics.nodes is not None or numerics.mesh == "uniform":
            nodes = min(int(math.ceil(numerics.uniform_nodes * f)), 5000)
            if nodes > numerics.uniform_nodes:
                changes["nodes"] = nodes
        elif numerics.band_resolution < 500.0:
            changes["band_resolution"] = min(numerics.band_resolution * f, 500.0)
    return dataclasses.replace(numerics, **changes) if changes else None


#: resolution ratios of the cheaper solve, tried in turn until one succeeds (a mesh of half
#: the resolution may not hold a small initial contact that a finer one holds)
COARSER_FACTORS = (2.0, math.sqrt(2.0))
#: a pair whose change is below this fraction of (spacing / tip zone)^2 may have crossed the
#: limit (the two pull-offs on either side of it, close together): a third solve, at a
#: quarter of the resolution, decides (:func:`estimate_error`). Chosen on the 30-32 scenes
#: of ``make error-coverage`` with a reference, where the pair's change missed the true
#: error in 2 scenes each of the fast and the accurate presets, every one with a change
#: below 0.05 (spacing / tip zone)^2, and checked on 21-26 scenes of a second seed
#: (``make extrapolation``, docs/numerics.md); about a third of the rows run the third solve
CROSSING_GATE = 0.05


def _halves(fine: Numerics, coarse: Numerics) -> bool:
    """Whether ``coarse`` is ``fine`` at half the resolution in space and time (not held at
    :func:`coarser`'s floors)."""
    space = (fine.uniform_nodes / coarse.uniform_nodes
             if fine.nodes is not None or fine.mesh == "uniform"
             else fine.band_resolution / coarse.band_resolution)
    return abs(space - 2.0) < 0.05 and abs(coarse.step / fine.step - 2.0) < 1e-9


def _over_budget(res: Result, check: Result, what: str) -> bool:
    """Whether the error estimate's ``check`` solve stopped at the scene's time budget; then
    ``res`` fails with a reason that starts "time budget:" and keeps its pull-off (the row's
    estimate would otherwise be the a-priori bound, or the pair without its crossing check,
    and its status would depend on how loaded the machine was; a user test of session 49
    found rows ``ok`` at balanced and accurate with the a-priori bound just below their
    tolerance). A ``res`` already failed this way is left as it is."""
    if not check.reason.startswith("time budget:"):
        return False
    if res.ok:
        res.status = "failed"
        res.reason = (f"{check.reason.split(';')[0]} (in {what}; the pull-off "
                      f"{res.pull_off:.6g} has no error estimate)")
    return True


def _crossing_check(res: Result, coarse: Result, change: float, how: str, solve):
    """(change, how) after a third solve at a quarter of the resolution: where the coarser
    pair's change over 4 (what it is at the finer pair's resolution for a second-order
    error) exceeds the finer pair's, the finer pair crossed the limit and the estimate takes
    the coarser pair's (:data:`CROSSING_GATE`)."""
    half = coarser(res.numerics, 2.0)
    quarter = coarser(half, 2.0)
    if not (_halves(half, quarter) and _halves(res.numerics, half)):
        return change, how          # a clamped resolution: no factor-2 pairs to compare
    coarsest = solve(quarter)
    if not coarsest.ok:
        _over_budget(res, coarsest, "the crossing check's solve at a quarter of the resolution")
        return change, how
    wider = abs(coarse.pull_off - coarsest.pull_off) / res.pull_off / 4.0
    if wider <= change:
        return change, how
    return wider, (f"the pull-off moves by {4.0 * wider:.2g} between 1/2 and 1/4 of the "
                   f"resolution ({coarsest.pull_off:.5g} vs {coarse.pull_off:.5g}), over 4")


#: the unloading of the error estimate's cheaper solves may make at most COARSE_WORK_FACTOR
#: times the fine solve's factorizations (the whole solve's, its relaxed start's included),
#: plus COARSE_WORK_FLOOR (counted at the unloading's chunks and re-meshings,
#: ``sweep.engine.budget.work_cap``); past that a cheaper solve is abandoned as failed, as
#: one that finds no equilibrium is. On 295 cheaper solves of the committed campaigns'
#: scenes (every fourth of the balanced threshold grid, ``make vr``'s and ``make fig3``'s,
#: and of the random samples auto, bem, protocol and process zone) the unloading made a
#: median 7 factorizations, 0.19 times the fine solve's, at most 2644 and 12 times (a
#: session-45 study; the committed campaigns' check holds their rows under the cap).
#: Near-elastic scenes at large Tabor parameters made far more: the tip, held by the nodes,
#: snaps from node to node at the coarser resolution, and each snap costs exact Newton (n
#: 0.8, k 0.9, mu 12, a0 2, rate 100 at ``Numerics.for_tolerance(0.01)``: the fine solve 6 s
#: and 1127 factorizations, the half-resolution one 37 s and 52143, failed; at k 0.99 the
#: row spent its whole 300 s budget and fell back to the a-priori estimate; now 35 s and
#: 53 s, the second with its sqrt-2 pair's estimate, docs/numerics.md)
COARSE_WORK_FACTOR = 20.0
COARSE_WORK_FLOOR = 2000


def _capped(solve: Callable[[Numerics], Result], numerics: Numerics, fine: Result) -> Result:
    """``solve(numerics)`` under the cheaper solves' work cap (COARSE_WORK_FACTOR), a failed
    Result where it is passed."""
    cap = int(COARSE_WORK_FACTOR * max(fine.factorizations, 0)) + COARSE_WORK_FLOOR
    with budget.work_cap(cap):
        try:
            return solve(numerics)
        except budget.OverWork as exc:
            return Result(scene=fine.scene, numerics=numerics, status="failed",
                          reason=f"abandoned, more work than {COARSE_WORK_FACTOR:g} times the "
                                 f"fine solve's: {exc}")


#: the order the error estimate assumes: the pair's change over f^ESTIMATE_ORDER - 1 (1.76
#: times the change at f = 2; at order 1 it would be the change itself). The misses of the
#: first-order rule on fresh samples (seeds 11 and 13: 87-93 % coverage at 3e-2 and 1e-2,
#: misses up to 1.76 times the estimate) were scenes where the band's convergence between the
#: pair's two resolutions is slower than first order (0.7-0.95 measured, docs/numerics.md);
#: chosen on seeds 7, 11 and 13 of ``make extrapolation``'s three solves, then checked on
#: seed 17, which it was not chosen on: coverage 0.97 / 1.00 / 0.97 against 0.93 / 0.97 /
#: 0.91 for the first-order rule (fast, balanced, accurate), median looseness 4.7-7.0; asked
#: for 3e-2 / 1e-2 / 1e-3, 0.97-1.00 covered on all four samples, median looseness 4.0-7.9
#: (docs/numerics.md, "The order the estimate assumes")
ESTIMATE_ORDER = 0.65


#: a pull-off taken before the crack tip moved this many fine spacings from its start is
#: checked at twice the resolution (:func:`_pinned_check`)
PINNED_TRAVEL = 1.0


def pinned(res: Result) -> bool:
    """Whether the unloading of ``res`` (a relaxed start) reached its pull-off before the
    crack tip moved :data:`PINNED_TRAVEL` fine spacings from where it started: a tip the
    nodes hold while the load falls past the contact's own minimum. There the estimate's
    coarser solve is held alike and agrees with the row: a user test of session 50 found
    rows ``ok`` 5-24 % off with estimates of 0.4-3 % (n 1.5-5 or sls, k 1e-4 to 1e-2, mu
    1-4, rate 0.1-10 at the fast and balanced presets; 246 rows, its 96 misses and 150
    others): of the 50 rows with a tip travel below one spacing, 49 estimates and 44 requests
    missed; of the 106 above it, 28 estimates and 1 request. A minimum at the start itself
    (a contact smaller than its pull-off radius) is not a held tip. A test protocol's
    retraction starts from the dwell's creeping contact and is not checked."""
    if res.scene.protocol() is not None:
        return False
    travel = res.a0_result - res.a_pulloff
    return (math.isfinite(travel) and math.isfinite(res.t_pulloff) and res.t_pulloff > 0.0
            and res.spacing > 0.0 and travel < PINNED_TRAVEL * res.spacing)


def finer(numerics: Numerics) -> Numerics:
    """The numerics of :func:`_pinned_check`'s solve: twice the resolution in space (band
    resolution, or nodes) and time (half the indentation step), no check of its own."""
    if numerics.nodes is not None or numerics.mesh == "uniform":
        return dataclasses.replace(numerics, nodes=2 * numerics.uniform_nodes,
                                   step=numerics.step / 2.0, pull_off_rtol=0.0)
    return dataclasses.replace(numerics, band_resolution=2.0 * numerics.band_resolution,
                               step=numerics.step / 2.0, pull_off_rtol=0.0)


def _pinned_check(res: Result, solve, extra: float) -> tuple[str | None, str | None]:
    """For a row whose tip was held (:func:`pinned`): a solve at twice the resolution, whose
    change against the row over 1 - 2^-p (p = ESTIMATE_ORDER: the coarser of a pair's error)
    plus ``extra`` (the Prony and zone terms) raises the estimate where larger. Returns
    (why the row is unresolved whatever its estimate: the finer solve's tip was held as
    well, where that solve's own pair would be the coarse one again, or the finer solve
    failed; else None, and how the estimate was raised, or None). Of the 50 held rows of the
    study (:func:`pinned`), the finer pair covered the error of all 19 whose finer solve's
    tip moved a spacing or more, and of 23 of the 31 whose finer tip was held too."""
    check = solve(finer(res.numerics))
    if _over_budget(res, check, "the check at twice the resolution of a held crack tip"):
        return None, None
    moved = (res.a0_result - res.a_pulloff) / res.spacing
    if not check.ok:
        return (f"the crack tip moved {moved:.2g} of a fine spacing before the pull-off, and "
                f"the check at twice the resolution failed ({shortened(check.reason, 100)})",
                None)
    change = abs(res.pull_off - check.pull_off) / res.pull_off
    estimate = change / (1.0 - 2.0 ** -ESTIMATE_ORDER) + extra
    how = None
    if estimate > res.error_estimate:
        res.error_estimate = estimate
        how = (f"the crack tip moved {moved:.2g} of a fine spacing before the pull-off; at "
               f"twice the resolution the pull-off moves by {change:.2g}: estimate "
               f"{estimate:.2g}")
    if pinned(check):
        moved_f = (check.a0_result - check.a_pulloff) / check.spacing
        return (f"the crack tip moved {moved:.2g} of a fine spacing before the pull-off, and "
                f"{moved_f:.2g} at twice the resolution ({check.pull_off:.5g} vs "
                f"{res.pull_off:.5g}): the nodes, not the contact, set the pull-off", how)
    return None, how


def relative_change(fine: float, coarse: float, over: float) -> float:
    """|fine - coarse| / |fine| / over, NaN where either is not finite or ``fine`` is 0: a
    quantity's error estimate from the pair (the hysteresis energy's,
    ``Result.hysteresis_error``)."""
    if not (math.isfinite(fine) and math.isfinite(coarse)) or fine == 0.0:
        return math.nan
    return abs(fine - coarse) / abs(fine) / over


def hysteresis_error(res: Result, coarse: float, over: float) -> float:
    """The estimated relative error of a test protocol's ``res.hysteresis_energy``: its
    change against ``coarse``, the coarser solve's, over ``over`` (the pull-off's factor),
    plus the trapezoid's on its own records (:func:`sweep.engine.postprocess.
    work_quadrature_error`, over 2^ESTIMATE_ORDER - 1: first order and second alike). The
    pair alone missed at low Tabor parameters: the few steps there set the trapezoid's error
    in both solves (``make hysteresis-coverage``: the pair alone covered 7 of 10 balanced
    rows, missing at mu 0.06-0.13; with the trapezoid's term 10 of 10, and 9 of 9 fast).
    NaN without a protocol."""
    if res.scene.protocol() is None:
        return math.nan
    quadrature = work_quadrature_error(res.trajectory, cycle_end(res))
    return (relative_change(res.hysteresis_energy, coarse, over)
            + quadrature / (2.0 ** ESTIMATE_ORDER - 1.0))


def estimate_error(res: Result, length: float, solve: Callable[[Numerics], Result]) -> None:
    """The error estimate of an ``ok`` result, in place: the pull-off change against a solve
    at ``1/f`` of the resolution in space and time (``solve(coarser(numerics, f))``, f = 2,
    else sqrt 2: :data:`COARSER_FACTORS`) over ``f^p - 1`` with p = :data:`ESTIMATE_ORDER`,
    plus the Prony fit's error (the same in both solves, so absent from their difference). A
    discretization of order ``p`` or more has an error of at most that: the estimate covers
    first and second order, and the slower convergence measured where the band is barely
    resolved. Where the change at f = 2 is small enough that the two
    solves may lie on either side of the limit (below :data:`CROSSING_GATE` (spacing /
    ``length``)^2), a third solve at a quarter of the resolution decides: the change between
    the two coarser solves over 4, where larger, stands in (:func:`_crossing_check`). Where
    every cheaper solve fails (or is abandoned past COARSE_WORK_FACTOR times the fine solve's
    factorizations: :func:`_capped`), the a-priori bound
    :func:`resolution_error` of the spacing against ``length`` (a_ref) stands in, and the
    reason says so. A result whose estimate exceeds ``numerics.pull_off_rtol`` is not ``ok``
    ("unresolved: ..."). The same pair estimates a test protocol's hysteresis energy
    (``hysteresis_error``, :func:`relative_change`; reported, not checked against the
    tolerance). Nothing is done when ``res`` failed or ``pull_off_rtol`` is 0."""
    tol = res.numerics.pull_off_rtol
    if not res.ok or tol <= 0:
        return
    prony = res.prony_error if math.isfinite(res.prony_error) else 0.0
    zone = zone_smoothing_error(res)
    terms = (f" + Prony {prony:.2g}" if prony > 0 else "") + (
        f" + the process zone's smoothed law {zone:.2g}" if zone > 0 else "")
    fine, solve = solve, lambda numerics: _capped(fine, numerics, res)
    for factor in COARSER_FACTORS:
        coarse = solve(coarser(res.numerics, factor))
        if _over_budget(res, coarse, f"the error estimate's solve at 1/{factor:.3g} the "
                                     f"resolution"):
            res.error_estimate = math.nan
            return
        if coarse.ok and factor != COARSER_FACTORS[-1] and pinned(coarse) and not pinned(res):
            # a coarser solve whose tip the nodes held overstates the change: the pair at
            # 1/sqrt 2 instead (docs/numerics.md, "A tip the nodes hold")
            continue
        if coarse.ok:
            change = abs(res.pull_off - coarse.pull_off) / res.pull_off
            how = (f"the pull-off moves by {change:.2g} on a mesh of 1/{factor:.3g} the "
                   f"resolution ({coarse.pull_off:.5g} vs {res.pull_off:.5g})")
            if factor == 2.0 and change < CROSSING_GATE * (res.spacing / length) ** 2:
                change, how = _crossing_check(res, coarse, change, how, solve)
                if not res.ok:      # its third solve stopped at the budget (_over_budget)
                    res.error_estimate = math.nan
                    return
            res.error_estimate = change / (factor ** ESTIMATE_ORDER - 1.0) + prony + zone
            res.hysteresis_error = hysteresis_error(res, coarse.hysteresis_energy,
                                                    factor ** ESTIMATE_ORDER - 1.0)
            how += (f": estimate {res.error_estimate:.2g} (change / ({factor:.3g}^"
                    f"{ESTIMATE_ORDER:g} - 1){terms})")
            break
    else:
        res.error_estimate = resolution_error(res.spacing, length) + prony + zone
        note = (f"error estimate a priori, {RESOLUTION_ERROR_K:g} (spacing/tip zone)^2: the "
                f"check on a coarser mesh failed ({shortened(coarse.reason, 120)})")
        res.reason = f"{res.reason}; {note}" if res.reason else note
        how = f"the a-priori estimate {res.error_estimate:.2g}"
    if pinned(res):
        held, raised = _pinned_check(res, fine, prony + zone)
        if not res.ok:              # its solve stopped at the budget (_over_budget)
            res.error_estimate = math.nan
            return
        if held is not None:
            res.status = "failed"
            res.reason = (f"unresolved: {held}; estimate {res.error_estimate:.2g}; "
                          f"{refine_advice(res.numerics)}")
            return
        how = raised or how
    if res.error_estimate > tol:
        res.status = "failed"
        advice = (ZONE_SMOOTHING_ADVICE if zone > tol else refine_advice(res.numerics))
        res.reason = f"unresolved: {how}, above pull_off_rtol = {tol:g}; {advice}"
