"""Per-step Newton solve on the gap and the Prony unloading loop (Numba kernels).

Each time step solves, for the nodal gaps h (docs/design.md sections 2 and 4),

    F(h) = h - g - A [ C_eff sigma(h) - H ] = 0,     g = -delta + h0 + r^2/2,

where A is the influence matrix (already scaled by the node spacing), sigma the
Lennard-Jones law and (C_eff, H) the hereditary-integral coefficients of the step.

Newton's Jacobian J = I - C_eff A diag(sigma'(h)) is factorized on the interacting nodes
and kept from step to step, exact in the crack-tip zone (its Schur complement refreshed as
the stiffness there moves) and as factorized in the contact interior (:mod:`kernels.jacobian`);
it is refactorized when the crack tip leaves the zone, when an iteration contracts the
residual by less than SLOW_CONTRACTION, when a line search fails with a stale factorization,
and at every iteration of the retries of a step whose solve failed. The line search (on
|F|_2) keeps every gap positive. A solve whose first update is predicted, from the
contraction measured before, to leave a residual below a tenth of the tolerance ends
without evaluating it (PREDICTED_RESIDUAL).

A compliant machine (a spring of stiffness K in series with the sphere, Physics.compliance
= 1/K, 0 for a rigid one) drives its own displacement D; the sphere's indentation is
delta = D - P(h)/K with P(h) = 2 pi wP . sigma(h) + P_tail (:func:`load`), so that

    F(h) = h - g(D) - P(h)/K - A [ C_eff sigma(h) - H ] = 0

and the Jacobian gains the rank-one term -(1/K) 1 (dP/dh)^T, dP/dh = 2 pi wP o sigma'(h)
(the tail's derivative, in the last node's gap alone, left out: :func:`load`):
Newton's direction is the kept factorization's with the Sherman-Morrison correction
(:func:`machine_direction`, one more solve, of J^-1 1, per direction). The loop's
indentation (RUN_DELTA) is then D; the records' delta is the sphere's, D - P/K. With
compliance 0 no term is added: the rigid path is the one computed before.

On a coarse mesh the discrete equilibrium path can fold (the crack tip snaps from node to
node); the loop then looks for the snapped state (:func:`snap`, :func:`relax`).

:func:`unload` takes its inputs in groups (named tuples: MeshArrays, Physics, StepControl,
RunState, Records) and runs each time step as named parts: :func:`predict_step`,
:func:`solve_step`, :func:`control_step`, :func:`accept_step`, :func:`stop_status` and
:func:`next_step`. The loop's scalars live in one float64 array named by RUN_*, its arrays
in a :data:`Work` tuple.

The parts called only from compiled code are inlined into their caller
(``inline='always'``): compiled on its own, each would be a library of its own that links
and machine-compiles again everything it calls (and one per literal argument), which made
most of a cold compile; inlined, they are compiled once, within :func:`newton` or
:func:`unload` (docs/performance.md, "The first run"). :func:`newton` and
:func:`stop_reached` are also called from Python and stay compiled on their own.

Status codes returned by :func:`unload`:
0 finished (stop criterion met), 1 no equilibrium at the minimum step, 2 step limit,
3 contact reached the mesh edge (domain too small), 4 the crack tip left the fine band of a
graded mesh (the driver widens it and starts again), 5 the time budget's deadline passed
(the Jacobian cache's, :func:`kernels.jacobian.set_deadline`: checked before every try of a
step, every Newton iteration and every relaxation iteration, so that one call ends within
about one iteration of it).
"""
from __future__ import annotations

from collections import namedtuple

import numpy as np
from numba import njit

from .blas import lu_factor, lu_solve
from .history import history_vector, step_coefficients, update_modes
from .interface import (TIP_GAP, ZONE_RATE, ZONE_SIZE, ZONE_SMOOTH, ZONE_XI, Interface,
                        crossing_radius, lj_traction, smoothing_rate, tail_load, traction,
                        traction_and_stiffness)
# invalidate and new_jacobian_cache are re-exported: the callers of newton/unload make the cache
from .clock import past
from .jacobian import (CACHE_CONTRACTION, CACHE_DEADLINE, CACHE_STATE,  # noqa: F401
                       STATE_EXACT, STATE_SCALED, STATE_VALID, apply_inverse, factorize,
                       invalidate, new_jacobian_cache, newton_direction, set_deadline)

STATUS_DONE = 0
STATUS_NEWTON_FAILED = 1
STATUS_STEP_LIMIT = 2
STATUS_DOMAIN = 3
STATUS_LEFT_BAND = 4
STATUS_TIME_BUDGET = 5
#: (internal) :func:`stop_status` when the run goes on
STATUS_RUNNING = -1

# stats vector layout (counters, incremented)
STAT_ITER = 0                 # Newton iterations
STAT_FACTOR = 1               # factorizations (restricted base or dense fallback)
STAT_REJECTED = 2             # steps rejected by the step control
STAT_FAILED_SOLVES = 3        # Newton solves that did not converge
STAT_ZONE = 4                 # refactorizations of the crack-tip zone's Schur complement
STAT_REFACTOR_ZONE = 5        # refactorizations: the crack tip left the zone
STAT_REFACTOR_LINESEARCH = 6  # refactorizations: a line search failed with a stale base
STAT_JUMPS = 7                # folds of the discrete path (snap / relax)
STAT_SUBSET = 8               # sum of |S| (factorized nodes) over the factorizations
STAT_RESIDUALS = 9            # residual evaluations (one N x N mat-vec each)
STAT_REFACTOR_SLOW = 10       # refactorizations: an iteration contracted poorly
STAT_REFACTOR_RETRY = 11      # refactorizations: exact Newton on the retry of a failed step
STAT_PREDICTED = 12           # solves ended on the predicted residual (no residual after)
N_STATS = 13

# ------------------------------------------------------------------ the kernel's inputs

#: the mesh: A (N, N) influence matrix (scaled by the spacing), r (N,) node positions
#: (a_ref units, r[0] = 0), wP (N,) load weights (P = 2 pi wP . sigma + the tail, :func:`load`),
#: tail = (r_end^2 - r_last^2)/2 the rigid gap's rise from the last node to the end of its hat,
#: r_end = 2 r_last - r_(last-1) (``sweep.engine.mesh.Mesh.tail_rise``; inf: no tail)
MeshArrays = namedtuple("MeshArrays", ["A", "r", "wP", "tail"])

#: the machine a solve loads the sphere through: its compliance (1/K, 0 a rigid machine) and
#: what the load the spring carries needs, the mesh's weights wP and tail (:data:`MeshArrays`,
#: :func:`load`); one argument of :func:`newton_machine`, :func:`relax_machine`
Machine = namedtuple("Machine", ["compliance", "wP", "tail"])

#: the scene's laws and loading (dimensionless, docs/design.md section 2): h0 and c of the
#: Lennard-Jones law, the Prony modes (weights, times) of Chat (times may be inf: a lumped
#: glassy constant), rate = r-hat (d D/dt = -rate h0, D the machine's displacement: the
#: indentation delta for a rigid machine); the process zone's opening-rate scale hdot_c
#: (d_ref / tau0; inf: none, the LJ law) and exponent xi
#: (:func:`kernels.interface.zone_factor`); compliance = 1/K, the machine's compliance in
#: d_ref per pi dg R (0, the default: a rigid machine, delta = D; else delta = D - P/K)
Physics = namedtuple("Physics", ["h0", "c", "weights", "times", "rate", "hdot_c", "xi",
                                 "compliance"], defaults=(0.0,))

#: the step control settings:
#: step_max, step_min: indentation steps (units of h0; of the machine's displacement D);
#: da_max: largest contact-radius change per step (a_ref);
#: step_tol: relative load error of the step predictor, |P(predicted) - P| / max(|P|,
#:     LOAD_ERROR_FLOOR), below which the step may grow beyond step_max (up to
#:     SMOOTH_STEP_FACTOR times) where the load evolves smoothly; 0 keeps every step <=
#:     step_max;
#: tol: Newton tolerance on max |F| (units of h0); max_iter: Newton iterations per solve;
#: max_steps: the run ends with STATUS_STEP_LIMIT when the records reach max_steps + 1;
#: stop_mode: 0 stop after pull-off and load recovery, 1 follow to separation, 2 as 0
#:     with a process zone (a contact that vanished before the load minimum followed on);
#: min_travel: crack-tip recession after the minimum required to stop (a_ref, see
#:     :func:`stop_reached`);
#: tip_lo, tip_hi: radii the crack tip must stay within (the well-resolved band of a graded
#:     mesh); leaving them ends the run with STATUS_LEFT_BAND;
#: da_max_pulloff: the largest contact-radius change per step (a_ref) near the load minimum
#:     (:func:`near_pulloff`), where the crack speed at pull-off is read (da_max: no change);
#: pulloff_zone: the crack-tip travel (a_ref) within which the load minimum counts as near
StepControl = namedtuple("StepControl", ["step_max", "step_min", "da_max", "step_tol", "tol",
                                         "max_iter", "max_steps", "stop_mode", "min_travel",
                                         "tip_lo", "tip_hi", "da_max_pulloff", "pulloff_zone"])

#: the run handed in (and, for q and step, back): h (N,) the gap at delta0 (the relaxed
#: elastic LJ solution at the start, the last accepted state when resuming); delta0 its
#: indentation (d_ref, used only when n == 0: a resumed run takes the time and indentation
#: of its last record); q (M, N) the modal history state, in/out (zeros for the relaxed
#: start; on return the modes of the last accepted step); n the records already written
#: (0: a new run, record 0 is the initial state; n >= 1: continue after record n - 1, the
#: stop rule sees all records); step (1,) the indentation step (units of h0), in/out (<= 0
#: starts at step_max; on return the step the run would take next; step[1], where given, the
#: time step that made h; step[2], where given, 1 during a lead-in: LEAD_GROWTH); sigma (N,)
#: the traction of h and h_prev (N,) the state before it, in/out: read when resuming with a
#: process zone (its traction depends on the step that made h, not on h alone, and Newton
#: starts from the extrapolation through both), on return those of the last accepted state
RunState = namedtuple("RunState", ["h", "delta0", "q", "n", "step", "sigma", "h_prev"])

#: the outputs: records t, delta, P, a, a_inner (length >= max_steps + 1: time, indentation,
#: load, contact radius at h_m and at h0) and h (N,), the gap of the last accepted step
Records = namedtuple("Records", ["t", "delta", "P", "a", "a_inner", "h"])

#: the unloading loop's arrays (:func:`new_work`): the last four accepted gaps (h newest),
#: Newton's start hp and the quadratic extrapolation h_pred, the tractions of the last
#: state, of hp and of h_pred, the step's Prony coefficients e and b (M,), H and g of the
#: equation, r^2/2 at the nodes, the modes q (M, N) (those of RunState), the ring of the
#: last LATTICE_HISTORY accepted states of the tip predictor (:func:`predict_lattice`): their
#: gaps past (LATTICE_HISTORY, N) and times and contact radii past_ta (2, LATTICE_HISTORY),
#: and the step's two starts, cubic and tip predictor's, starts (2, N); the process zone's
#: state over the step, zone (ZONE_SIZE; :func:`kernels.interface.traction`), and the gap
#: its opening is measured from, ref (N; :func:`zone_step`)
Work = namedtuple("Work", ["h", "h_prev", "h_prev2", "h_prev3", "hp", "h_pred", "sigma",
                           "sig_new", "sigma_pred", "e", "b", "H", "g", "r2half", "q",
                           "past", "past_ta", "starts", "zone", "ref"])

# the loop's scalars: one float64 array (N_RUN), positions named RUN_*
RUN_T = 0          # time of the last accepted state
RUN_DELTA = 1      # its machine displacement D (d_ref; the indentation for a rigid machine)
RUN_A = 2          # its contact radius at h_m (a_ref)
RUN_DD = 3         # the indentation step being tried (d_ref)
RUN_DT = 4         # its time step
RUN_CEFF = 5       # its C_eff
RUN_DT_PREV = 6    # the time steps of the last three accepted states (0 until they exist)
RUN_DT_PREV2 = 7
RUN_DT_PREV3 = 8
RUN_PAST = 9       # accepted states written to the tip predictor's ring (Work.past)
RUN_TIP_MADE = 10  # 1 where the step's tip predictor was made (Work.starts[1])
RUN_TIP_SCORE = 11  # log2 of the tip predictor's error over the cubic's, averaged over the
                    # steps where both were made (:func:`score_starts`)
RUN_ZONE_RAMP = 12  # a process zone's first step by zone_ramp: 1 to be tried, 2 tried
RUN_LEAD_STEP = 13  # a lead-in's step as tried first (0: no lead-in), the floor of its halving
N_RUN = 14

# outcomes of :func:`solve_step`
SOLVED = 0         # Newton converged: hp is the new state
HALVED = 1         # Newton failed: the step was halved, try again
SNAPPED = 2        # at a fold of the path: hp is the snapped state (no step-error estimate)
FAILED = 3         # no equilibrium at the smallest step

# ------------------------------------------------------------------ thresholds

#: an iteration with a stale factorization that reduces |F|_2 by less than this factor
#: refactorizes before the next one (fresh, the chord iteration contracts by 1e-4 to 1e-3 on
#: the reference scenes; 0.5 let it crawl at 0.46 for ten iterations; 0.1 and 0.03 cost
#: the same on the vs-numpy scenes, 0.03 refactorizes 5x more on the fast n = 0.4 one).
#: Not with the drift-scaled chord (state[STATE_SCALED], the protocol's march): its linear
#: contraction stays at 0.002-0.04 there, so a slow iteration is the start's nonlinearity at
#: the advancing crack tip, which a new factorization does not speed
SLOW_CONTRACTION = 0.1

#: a solve ends after its first update without the residual at the new point when the
#: residual predicted there, |F|_max times the contraction last measured, is at most this
#: fraction of the tolerance (the simplified-Newton stopping rule of Hairer and Wanner,
#: Solving ODEs II, section IV.8) ...
PREDICTED_RESIDUAL = 0.1
#: ... and each such solve multiplies the contraction estimate by this factor, so that
#: within a few steps a residual is computed again and the contraction measured anew
CONTRACTION_GROWTH = 2.0

#: a Newton update may close a gap by at most this fraction of it (every gap stays positive)
MAX_GAP_CLOSURE = 0.7
#: the line search accepts a step length lam when |F|_2 falls by the factor 1 - ARMIJO lam
ARMIJO = 1e-4
#: ... else it multiplies lam by this factor ...
BACKTRACK = 0.5
#: ... at most this many times
LINE_SEARCH_STEPS = 16

#: pseudo-time step of the first relaxation iteration (:func:`relax`) ...
RELAX_DTAU_START = 0.1
#: ... an iteration whose |F|_2 grows by more than this factor (or is not finite) is
#: rejected ...
RELAX_DIVERGENCE = 1e3
#: ... and repeated with the pseudo-time step multiplied by this factor ...
RELAX_DTAU_CUT = 0.1
#: ... down to this pseudo-time step, below which the relaxation gives up
RELAX_DTAU_MIN = 1e-10
#: the pseudo-time step grows by at most this factor per iteration ...
RELAX_DTAU_GROWTH = 10.0
#: ... up to this value (plain Newton)
RELAX_DTAU_MAX = 1e12
#: pseudo-time iterations allowed for one snap of the crack tip at a fold
RELAX_MAX_ITER = 300

#: the snapped state is looked for shifted inward by 1, 2, ... this many nodes
SNAP_MAX_SHIFT = 6
#: nodes more than this far inside the crack tip keep their gap in a shifted profile (the
#: contact interior does not move with the tip)
SNAP_KEEP_INSIDE = 20
#: a failed step is halved down to this fraction of the largest step before it is taken
#: for a fold of the discrete path (and the snapped state is looked for)
SNAP_STEP_FRACTION = 1.0 / 8.0

#: relative margin of the comparisons of a step with its bounds (steps change by factors
#: of 2 and are clipped at the bounds: a step within this of a bound is at the bound)
STEP_RTOL = 1e-4

#: steps in a row whose contact-radius change is below EASY_DA_FRACTION * da_max before
#: the step doubles (steps change by factors of 2 only)
EASY_STEPS = 8
EASY_DA_FRACTION = 0.3
#: a step rejected for its radius change is halved until the change, assumed proportional
#: to the step, is below this fraction of da_max
REJECT_TARGET = 0.8
#: where the load evolves smoothly the step grows beyond step_max, up to this factor, while
#: the predictor's load error stays below step_tol and the crack tip moves by less than
#: SMOOTH_DA_FRACTION da_max per step
SMOOTH_STEP_FACTOR = 8.0
SMOOTH_DA_FRACTION = 0.6
#: a lead-in (RunState ``step[2]`` set: a test protocol's retraction whose first step, the
#: march's last time step, is shorter than step_max) grows its step by this factor after
#: every accepted step that moved the crack tip by less than EASY_DA_FRACTION da_max, up to
#: step_max, where the ordinary control takes over; the dwell's growth
#: (``sweep.engine.protocol.DWELL_GROWTH``): the load relaxes on the approach's time scale
#: first, and the steps grow geometrically in time, as the dwell's do
LEAD_GROWTH = 1.3
#: a process zone's first step may take this many times max_iter Newton iterations: its factor
#: jumps from 1 at rest to 1 + (rate h0/hdot_c)^xi at once, and Newton converges slowly but
#: surely there (25-34 iterations on n 0.4, k 0.1, mu 3.24, delta0 4.95, rate 10^0.5, pz_v0 the
#: crack speed; with max_iter alone that scene failed at the minimum step, and the rate-100
#: scene of ``make pz-check`` halved its first step three times and refactorized 107 times)
FIRST_ZONE_ITER = 4
#: where both starts of a process zone's first step fail at the smallest step that halving
#: reaches, the step is solved again by continuation in the zone's strength: the opening
#: rate's scale zone[ZONE_RATE] times ZONE_RAMP_START, raised by ZONE_RAMP_FACTOR a solve
#: (each from the last solve's state, the first from rest) to its own value; a stage that
#: fails is retried at the geometric mean of the last good scale and its own, at most
#: ZONE_RAMP_SOLVES solves in all. Halving the step cannot help there: the rigid opening's
#: rate, and so the zone's factor, does not depend on the step. A strong zone at a fast
#: unloading (q ~ 1e4: n 0.3646, k 0.8455, mu 0.3787, a0 2.29, rate 6991, pz_v0 0.4473, xi
#: 0.638) failed its first step from both starts at every step down to the minimum
#: (docs/design.md, "The process zone in the BEM")
ZONE_RAMP_START = 1e-6
ZONE_RAMP_FACTOR = 10.0
ZONE_RAMP_SOLVES = 40
#: with a process zone, Newton's cubic start is settled at the crack tip first
#: (:func:`settle_tip`): the gaps of this many nodes either side of the last state's tip, by
#: ZONE_SETTLE_ITER Newton iterations on those nodes alone. The rate term makes the gap
#: equation there much stiffer than the LJ law's, and the start's residual was ten times the
#: LJ scene's (above 1e3 tol at 370 of 485 steps, against 175 of 429), its maximum at the
#: tip: Newton took two iterations a step where LJ takes one (n 0.4, k 0.1, mu 3.24, delta0
#: 4.95, rate 10^0.5, pz_v0 the crack speed: 1.93 iterations a step, 1.26 settled; 6 or 12
#: nodes, or 1 or 3 iterations, within the noise of 8 and 2; docs/performance.md, "The process
#: zone's cost"). Not for the LJ law: there the start is near enough, and the settle's
#: refactorizations cost more than it saves (four of six bench scenes slower)
ZONE_SETTLE_NODES = 8
ZONE_SETTLE_ITER = 2
#: the predictor never puts a gap below this fraction of the last accepted one
PREDICT_FLOOR = 0.5
#: the tip predictor (:func:`predict_lattice`) looks this many accepted states back for the
#: one where the crack tip was one node further along its path; a tip slower than a node in
#: that many steps keeps the cubic start
LATTICE_HISTORY = 16
#: the tip predictor's band: nodes from LATTICE_BAND_IN inside the crack tip to
#: LATTICE_BAND_OUT outside it start from it (the rest from the cubic extrapolation)
LATTICE_BAND_IN = 48
LATTICE_BAND_OUT = 24
#: Newton starts from the tip predictor where its error on the band, over the cubic's, has
#: been below this (log2: half) on average over the last steps where both were made: where
#: the nodes hold the tip (coarse meshes) it is below a tenth of the cubic's at most steps;
#: where the tip slides, 1.7-200 times the cubic's (medians; docs/performance.md)
LATTICE_SCORE_USE = -1.0
#: the weight of the last step in that average (the weights of older steps halve each step)
LATTICE_SCORE_WEIGHT = 0.5
#: spacings equal within this relative difference are one spacing (the tip predictor's band)
SPACING_RTOL = 1e-6
#: the predictor's load error is relative to max(|P|, this) (units of pi dg R; absolute
#: where the load passes through zero)
LOAD_ERROR_FLOOR = 1.0

#: the pull-off is past once the load has recovered by this fraction of |P_min| ...
RECOVERY = 0.05
#: ... and by at least this much (units of pi dg R; the elastic pull-off is about 1.5),
RECOVERY_FLOOR = 0.05
#: ... at least this many steps after the minimum, and the crack tip has receded from its
#: radius at the minimum by at least ``min_travel`` (the caller gives a few node spacings:
#: a lattice dip of the load, the tip snapping by one node, cannot end the run)
RECOVERY_STEPS = 5
#: following to separation ends when the contact is lost and |P| < this fraction of |P_min|
SEPARATION_LOAD = 1e-3


@njit(cache=True, inline='always')
def _copy(src, dst):
    """dst[:] = src as a loop (a slice assignment compiles Numba's shape-mismatch message,
    string formatting and all: about 2 s of a cold compile)."""
    if dst.size != src.size:
        raise ValueError("_copy: arrays of different sizes")
    for i in range(src.size):
        dst[i] = src[i]


@njit(cache=True)
def stop_reached(P, a, n, i_min, stop_mode, min_travel):
    """The one stop rule, on the records P[:n], a[:n] with the load minimum at ``i_min``.

    stop_mode 0 (pull-off): past a tensile minimum by RECOVERY_STEPS steps, the load
    recovered by max(RECOVERY |P_min|, RECOVERY_FLOOR) and the tip receded by
    ``min_travel`` (a_ref); or the contact is lost after the minimum.
    stop_mode 1 (separation): contact lost and the load back to SEPARATION_LOAD |P_min|.
    stop_mode 2 (pull-off with a process zone): as 0, but where the contact had vanished by
    the minimum (a = 0 there) the load recovered as in 0 (with no tip to recede): the zone
    may hold the surfaces after the contact's end while the load still falls, and a rise of
    one step is not yet the pull-off.
    """
    P_min = P[i_min]
    P_now = P[n - 1]
    a_now = a[n - 1]
    if stop_mode != 1:
        recovered = (P_min < 0.0 and n - 1 - i_min >= RECOVERY_STEPS
                     and P_now - P_min > max(RECOVERY * abs(P_min), RECOVERY_FLOOR))
        if recovered and a[i_min] - a_now >= min_travel:
            return True
        if a_now == 0.0 and n - 1 - i_min >= 1:
            return stop_mode == 0 or a[i_min] > 0.0 or recovered
        return False
    return a_now == 0.0 and P_now > P_min and abs(P_now) < SEPARATION_LOAD * abs(P_min)


@njit(cache=True, inline='always')
def residual(h, g, A, ceff, H, law, sig, w, F):
    """F = h - g - A (ceff sigma(h) - H); returns max |F|. sig, w are work arrays; ``law``
    the interface law (:data:`kernels.interface.Interface`)."""
    traction(h, law.h_old, law.zone, law.h0, law.c, sig)
    for j in range(h.size):
        w[j] = ceff * sig[j] - H[j]
    u = A @ w
    norm = 0.0
    for i in range(h.size):
        F[i] = h[i] - g[i] - u[i]
        if abs(F[i]) > norm:
            norm = abs(F[i])
    return norm


@njit(cache=True, inline='always')
def machine_residual(h, g, A, ceff, H, law, machine, sig, w, F):
    """:func:`residual` with a compliant machine (:data:`Machine`): F - compliance P(h),
    P = 2 pi wP . sigma + the Lennard-Jones tail beyond the mesh (:func:`load`) (the
    indentation is D - compliance P, ``g`` that of D); exactly :func:`residual` for
    compliance 0. Returns max |F|."""
    norm = residual(h, g, A, ceff, H, law, sig, w, F)
    compliance = machine.compliance
    if compliance == 0.0:
        return norm
    cP = compliance * load(sig, machine.wP, h, machine.tail, law.h0, law.c)
    norm = 0.0
    for i in range(h.size):
        F[i] -= cP
        if abs(F[i]) > norm:
            norm = abs(F[i])
    return norm


@njit(cache=True, inline='always')
def machine_direction(dh, d, A, compliance, wP, cache):
    """Newton's direction ``dh`` = -J^-1 F of the kept factorization corrected in place for a
    compliant machine, whose Jacobian is J - compliance 1 v^T with v = dP/dh = 2 pi wP o
    sigma'(h) (``d``): by Sherman-Morrison, dh + compliance y (v . dh) / (1 - compliance
    v . y) with y = J^-1 1. False where the denominator vanishes (the spring's fold).
    The tail of the load beyond the mesh (:func:`load`) is left out of v: its derivative,
    in the last node's gap alone, is 2 pi c (q^3 - q^9), q = h0/h_end, about 2 pi c / 60^3
    at the default tail_gap, against v's entries of order 2 pi wP_j c at the crack tip;
    Newton converges with it left out (its residual includes the tail)."""
    y = apply_inverse(np.ones(dh.size), A, cache)
    vy, vdh = 0.0, 0.0
    for i in range(dh.size):
        v = 2.0 * np.pi * wP[i] * d[i]
        vy += v * y[i]
        vdh += v * dh[i]
    den = 1.0 - compliance * vy
    if den == 0.0 or not np.isfinite(den):
        return False
    f = compliance * vdh / den
    for i in range(dh.size):
        dh[i] += f * y[i]
    return True


@njit(cache=True, inline='always')
def positive_step(h, dh):
    """Largest step length <= 1 along ``dh`` that closes no gap by more than
    MAX_GAP_CLOSURE of it."""
    lam = 1.0
    for i in range(h.size):
        if dh[i] < 0.0:
            lim = -MAX_GAP_CLOSURE * h[i] / dh[i]
            if lim < lam:
                lam = lim
    return lam


@njit(cache=True, inline='always')
def _norm2(F):
    s = 0.0
    for i in range(F.size):
        s += F[i] * F[i]
    return np.sqrt(s)


@njit(cache=True, inline='always')
def _refactorize(h, A, ceff, law, cache, stats, reason):
    m = factorize(h, A, ceff, law.h0, law.c, law.h_old, law.zone, cache)
    stats[STAT_FACTOR] += 1
    stats[STAT_SUBSET] += m
    if reason >= 0:
        stats[reason] += 1


@njit(cache=True, inline='always')
def _direction(h, F, A, ceff, law, machine, sig, d, dr, cache, stats):
    """Newton's direction at ``h`` (residual ``F``) with the cached factorization, made again
    once when it no longer fits (the crack tip left the zone), corrected for a compliant
    machine (:func:`machine_direction`). Returns (dh, ok, refactorized); ok is False when
    even the fresh factorization gives none."""
    traction_and_stiffness(h, law.h_old, law.zone, law.h0, law.c, sig, d, dr)
    dh, ok = newton_direction(F, d, dr, A, ceff, cache, stats, STAT_ZONE)
    refactorized = False
    if not ok:
        _refactorize(h, A, ceff, law, cache, stats, STAT_REFACTOR_ZONE)
        dh, ok = newton_direction(F, d, dr, A, ceff, cache, stats, STAT_ZONE)
        refactorized = True
    if ok and machine.compliance != 0.0:
        ok = machine_direction(dh, d, A, machine.compliance, machine.wP, cache)
    return dh, ok, refactorized


@njit(cache=True, inline='always')
def _end_predicted(h, dh, theta, stats):
    """Take the full update ``dh`` without its residual (predicted below tolerance): the
    contraction estimate ``theta[0]`` grows by CONTRACTION_GROWTH (at most 1)."""
    for i in range(h.size):
        h[i] += dh[i]
    theta[0] = min(CONTRACTION_GROWTH * theta[0], 1.0)
    stats[STAT_PREDICTED] += 1


@njit(cache=True)
def newton(h, g, A, ceff, H, law, tol, max_iter, cache, stats):
    """Solve F(h) = 0 in place, starting from ``h``, with the interface law ``law``
    (:data:`kernels.interface.Interface`) and a rigid machine: :func:`newton_machine` with
    compliance 0. Returns True on convergence."""
    return newton_machine(h, g, A, ceff, H, law, tol, max_iter, cache, stats,
                          Machine(0.0, np.zeros(h.size), np.inf))


@njit(cache=True)
def newton_machine(h, g, A, ceff, H, law, tol, max_iter, cache, stats, machine):
    """Solve F(h) = 0 in place from ``h`` with the interface law ``law``
    (:data:`kernels.interface.Interface`) and the :data:`Machine` ``machine``: its compliance
    (1/K; 0 rigid), the load's weights and the mesh's tail (:func:`load`)
    (:func:`machine_residual`, :func:`machine_direction`).
    True on convergence; False past the cache's deadline (read before every iteration,
    :func:`kernels.jacobian.set_deadline`). The cache's factorization is reused, its crack-tip
    zone kept exact (:func:`kernels.jacobian.newton_direction`); it is rebuilt when the crack
    tip left the zone, when a stale one contracts the residual by less than SLOW_CONTRACTION,
    when a line search fails with a stale one, and at every iteration while
    ``state[STATE_EXACT]`` is set.

    Converged means max |F| <= ``tol``: computed, or, after a first full update, predicted
    below PREDICTED_RESIDUAL ``tol`` as |F| times the contraction last measured (kept in
    ``cache[CACHE_CONTRACTION]``; each solve so ended doubles it): it saves the one mat-vec
    of a solve that a single chord update converges.
    """
    state = cache[CACHE_STATE]
    theta = cache[CACHE_CONTRACTION]
    N = h.size
    sig, d, dr, w = np.empty(N), np.empty(N), np.empty(N), np.empty(N)
    F, Ft, ht = np.empty(N), np.empty(N), np.empty(N)
    norm = machine_residual(h, g, A, ceff, H, law, machine, sig, w, F)
    stats[STAT_RESIDUALS] += 1
    if norm <= tol:
        return True
    fresh = False
    if state[STATE_VALID] == 0:
        _refactorize(h, A, ceff, law, cache, stats, -1)
        fresh = True
    for it in range(max_iter):
        if past(cache[CACHE_DEADLINE][0]):
            return False
        stats[STAT_ITER] += 1
        if state[STATE_EXACT] == 1 and not fresh:
            _refactorize(h, A, ceff, law, cache, stats, STAT_REFACTOR_RETRY)
            fresh = True
        dh, ok, refactorized = _direction(h, F, A, ceff, law, machine, sig, d, dr, cache,
                                          stats)
        fresh = fresh or refactorized
        if not ok:       # singular even on a fresh factorization: give up
            return False
        lam = positive_step(h, dh)
        if (it == 0 and lam == 1.0 and state[STATE_EXACT] == 0
                and theta[0] * norm <= PREDICTED_RESIDUAL * tol):
            _end_predicted(h, dh, theta, stats)
            return True
        # backtracking on the merit |F|_2 (Newton directions descend it); the max norm
        # decides convergence
        accepted = False
        n2 = _norm2(F)
        nt2 = n2
        for _ls in range(LINE_SEARCH_STEPS):
            for i in range(N):
                ht[i] = h[i] + lam * dh[i]
            nt = machine_residual(ht, g, A, ceff, H, law, machine, sig, w, Ft)
            stats[STAT_RESIDUALS] += 1
            nt2 = _norm2(Ft)
            if nt2 < (1.0 - ARMIJO * lam) * n2:
                accepted = True
                break
            lam *= BACKTRACK
        if not accepted:
            if fresh:        # a line search failed on an exact Jacobian: give up
                return False
            _refactorize(h, A, ceff, law, cache, stats, STAT_REFACTOR_LINESEARCH)
            fresh = True
            continue
        theta[0] = nt / norm if lam == 1.0 else 1.0
        for i in range(N):
            h[i] = ht[i]
            F[i] = Ft[i]
        norm = nt
        if norm <= tol:
            return True
        fresh = not fresh and nt2 > SLOW_CONTRACTION * n2 and state[STATE_SCALED] == 0
        if fresh:
            _refactorize(h, A, ceff, law, cache, stats, STAT_REFACTOR_SLOW)
    return False


@njit(cache=True, inline='always')
def relax(h, g, A, ceff, H, law, tol, max_iter, stats, deadline):
    """:func:`relax_machine` with a rigid machine (compliance 0), in place; True on success.
    ``deadline``: the kernels' clock time past which it gives up (a Jacobian cache's
    ``cache[CACHE_DEADLINE][0]``; inf: none)."""
    return relax_machine(h, g, A, ceff, H, law, Machine(0.0, np.zeros(h.size), np.inf), tol,
                         max_iter, stats, deadline)


@njit(cache=True, inline='always')
def relax_machine(h, g, A, ceff, H, law, machine, tol, max_iter, stats, deadline):
    """Pseudo-transient continuation to a *stable* equilibrium, in place; True on success.

    Integrates the relaxation dh/dtau = -F(h) with linearly implicit Euler steps,
    (I/dtau + J) dh = -F, and the switched-evolution-relaxation rule
    dtau <- dtau |F_old| / |F_new| (RELAX_DTAU_*): small dtau follows the flow, large dtau
    is Newton. J = A K (compliance times the energy Hessian), so the flow is attracted to
    stable equilibria. Used where the discrete equilibrium path folds (the crack tip
    snapping from one node to the next), as the physical system would. One dense
    factorization per iteration: a fallback, not the main path. A compliant machine
    (:data:`Machine` ``machine``: compliance = 1/K, the load's weights wP and the mesh's
    tail) adds -compliance 2 pi wP_j sigma'_j to every row of J (:func:`machine_residual`;
    the tail's derivative left out, as in :func:`machine_direction`). False once
    ``deadline`` (the kernels' clock, :mod:`kernels.clock`; inf: none) has passed, read before
    every iteration.
    """
    N = h.size
    sig = np.empty(N)
    d = np.empty(N)
    w = np.empty(N)
    F = np.empty(N)
    Ft = np.empty(N)
    ht = np.empty(N)
    norm = machine_residual(h, g, A, ceff, H, law, machine, sig, w, F)
    n2 = _norm2(F)
    dtau = RELAX_DTAU_START
    J = np.empty((N, N))
    piv = np.empty(N, np.int32)
    rhs = np.empty((1, N))
    dh = rhs[0]
    for it in range(max_iter):
        if norm <= tol:
            return True
        if past(deadline):
            return False
        stats[STAT_ITER] += 1
        stats[STAT_FACTOR] += 1
        traction_and_stiffness(h, law.h_old, law.zone, law.h0, law.c, sig, d, w)
        for i in range(N):
            for j in range(N):
                J[i, j] = -ceff * A[i, j] * d[j]
            J[i, i] += 1.0 + 1.0 / dtau
        if machine.compliance != 0.0:
            for j in range(N):
                spring = machine.compliance * 2.0 * np.pi * machine.wP[j] * d[j]
                for i in range(N):
                    J[i, j] -= spring
        # LAPACK's LU through kernels.blas (np.linalg.solve: 5 s of a cold compile)
        if lu_factor(J, piv) != 0:
            raise np.linalg.LinAlgError("relax: the Jacobian is singular")
        for i in range(N):
            dh[i] = -F[i]
        lu_solve(J, piv, rhs)
        lam = positive_step(h, dh)
        for i in range(N):
            ht[i] = h[i] + lam * dh[i]
        nt = machine_residual(ht, g, A, ceff, H, law, machine, sig, w, Ft)
        nt2 = _norm2(Ft)
        if not np.isfinite(nt2) or nt2 > RELAX_DIVERGENCE * n2:
            dtau *= RELAX_DTAU_CUT
            if dtau < RELAX_DTAU_MIN:
                return False
            continue
        for i in range(N):
            h[i] = ht[i]
            F[i] = Ft[i]
        dtau = min(dtau * min(n2 / nt2, RELAX_DTAU_GROWTH), RELAX_DTAU_MAX)
        norm, n2 = nt, nt2
    return norm <= tol


@njit(cache=True, inline='always')
def snap(mesh, physics, work, ceff, tol, max_iter, hm, cache, stats):
    """Newton from the gap profile ``work.h`` outside the crack tip shifted inward by 1 to
    SNAP_MAX_SHIFT nodes (the nodes more than SNAP_KEEP_INSIDE inside it kept).

    Near a fold of the discrete path the stable state the tip snaps to is, locally, the
    same profile one node further in; starting Newton there finds it in a few iterations.
    Accepts only a solution whose contact radius (at the gap ``hm``) moved inward.
    Solution in ``work.hp``.
    """
    h, hp, r = work.h, work.hp, mesh.r
    N = h.size
    a_old = crossing_radius(h, r, hm)
    i_tip = max(int(np.searchsorted(r, a_old)) - 1, 0)
    for shift in range(1, SNAP_MAX_SHIFT + 1):
        i0 = max(i_tip - SNAP_KEEP_INSIDE, 1)
        for i in range(N):
            if i < i0:
                hp[i] = h[i]
            elif i + shift < N:
                hp[i] = h[i + shift]
            else:
                hp[i] = h[N - 1] + (h[N - 1] - h[N - 2]) * (i + shift - N + 1)
        if newton_machine(hp, work.g, mesh.A, ceff, work.H,
                          Interface(physics.h0, physics.c, work.ref, work.zone), tol, max_iter,
                          cache, stats, Machine(physics.compliance, mesh.wP, mesh.tail)):
            if crossing_radius(hp, r, hm) < a_old:
                return True
    return False


@njit(cache=True, inline='always')
def load(sigma, wP, h, tail, h0, c):
    """P = 2 pi sum_j w_j sigma_j + P_tail (positive = compressive): the tractions ``sigma``
    of the gaps ``h`` on the mesh, and the Lennard-Jones attraction beyond its end
    (:func:`kernels.interface.tail_load`), the gap continued there as the rigid sphere's
    from the last node's: h_end = h[-1] + ``tail`` (:data:`MeshArrays`; inf: no tail). A
    process zone's factor is 1 beyond the mesh (it acts at the crack tip, far inside). The
    tail's derivative (in h[-1] alone, 2 pi c (q^3 - q^9), q = h0/h_end: about 3e-5 c at the
    default tail_gap 60) is left out of the Newton Jacobians that involve the load (the
    machine's, :func:`machine_direction`; the held step's, ``kernels.protocol``): Newton
    converges without it, the residuals include the tail."""
    return 2.0 * np.pi * np.dot(wP, sigma) + tail_load(h[h.size - 1] + tail, h0, c)


@njit(cache=True, inline='always')
def predict_cubic(h, h_prev, h_prev2, h_prev3, dt, dt_prev, dt_prev2, dt_prev3, hp):
    """Starting gap of Newton: cubic (Lagrange) extrapolation through the last four
    accepted states, floored at PREDICT_FLOOR of the last gap; False (nothing written)
    before four states exist."""
    if not dt_prev3 > 0.0:
        return False
    t1 = -dt_prev
    t2 = t1 - dt_prev2
    t3 = t2 - dt_prev3
    l0 = (dt - t1) * (dt - t2) * (dt - t3) / ((-t1) * (-t2) * (-t3))
    l1 = dt * (dt - t2) * (dt - t3) / (t1 * (t1 - t2) * (t1 - t3))
    l2 = dt * (dt - t1) * (dt - t3) / (t2 * (t2 - t1) * (t2 - t3))
    l3 = dt * (dt - t1) * (dt - t2) / (t3 * (t3 - t1) * (t3 - t2))
    for i in range(h.size):
        hp[i] = max(l0 * h[i] + l1 * h_prev[i] + l2 * h_prev2[i] + l3 * h_prev3[i],
                    PREDICT_FLOOR * h[i])
    return True


@njit(cache=True, inline='always')
def _ring_crossing(past_ta, row, count, level):
    """In the tip predictor's ring (``count`` states written, LATTICE_HISTORY kept), the
    newest two consecutive states between which row ``row`` of ``past_ta`` (0 time, 1
    contact radius) passed ``level``: (ring index of the older one, fraction of the way
    to the newer one); (-1, 0) where it did not within the ring."""
    K = past_ta.shape[1]
    x = past_ta[row]
    for back in range(min(count, K) - 1):
        j1 = (count - 1 - back) % K
        j = (j1 - 1) % K
        if (x[j] - level) * (x[j1] - level) <= 0.0 and x[j] != x[j1]:
            return j, (level - x[j]) / (x[j1] - x[j])
    return -1, 0.0


@njit(cache=True)
def _uniform_band(r, tip, ds):
    """The tip predictor's band [lo, hi) around node ``tip``, LATTICE_BAND_IN nodes inside
    and LATTICE_BAND_OUT outside, cut to the nodes spaced ``ds`` (and one node off either
    end of the mesh, so that a node's neighbours exist)."""
    N = r.size
    lo, hi = tip, tip
    tol = SPACING_RTOL * ds
    while lo > max(tip - LATTICE_BAND_IN, 1) and abs(r[lo] - r[lo - 1] - ds) <= tol:
        lo -= 1
    while hi < min(tip + LATTICE_BAND_OUT, N - 1) and abs(r[hi + 1] - r[hi] - ds) <= tol:
        hi += 1
    return lo, hi


@njit(cache=True)
def predict_lattice(r, h, past, past_ta, count, dt, hp):
    """Newton's start near the crack tip (overwrites ``hp`` there; True where it did): on a
    mesh the tip does not slide at a steady speed but is held and released by the nodes it
    crosses, so the gaps next to it move in a cycle that repeats, node by node, each time the
    tip has moved one spacing. The start is the last gap ``h`` plus the change the same step
    ``dt`` made one cycle earlier, taken one node along: from the ring of accepted states
    (``past``, times and contact radii ``past_ta``, ``count`` written), the time tau at which
    the contact radius was one spacing from its last value a on the far side of its motion
    (interpolated between states) and the gaps at tau and tau + dt (interpolated in time),
    h_i + [h(tau + dt) - h(tau)]_(i + s), s = +1 for a receding tip (-1 advancing), on the
    nodes of the band around a. Nothing is written while the tip has not moved one spacing
    within the ring or when it moved more than that within one step."""
    K = past.shape[0]
    if count < 3:
        return False
    last, prev = (count - 1) % K, (count - 2) % K
    a, a_prev = past_ta[1, last], past_ta[1, prev]
    tip = np.searchsorted(r, a)
    if a == a_prev or tip < 1 or tip >= r.size:
        return False
    ds = r[tip] - r[tip - 1]
    s = 1 if a < a_prev else -1
    m, f = _ring_crossing(past_ta, 1, count, a + s * ds)
    if m < 0:
        return False
    m1 = (m + 1) % K
    tau = past_ta[0, m] + f * (past_ta[0, m1] - past_ta[0, m])
    q, g = _ring_crossing(past_ta, 0, count, tau + dt)
    if q < 0:
        return False
    q1 = (q + 1) % K
    lo, hi = _uniform_band(r, tip, ds)
    for i in range(max(lo, -s), min(hi, r.size - max(s, 0))):
        j = i + s
        dh = (past[q, j] + g * (past[q1, j] - past[q, j])
              - past[m, j] - f * (past[m1, j] - past[m, j]))
        hp[i] = max(h[i] + dh, PREDICT_FLOOR * h[i])
    return True


@njit(cache=True)
def score_starts(r, starts, h, a):
    """log2 of max |start - h| of the tip predictor's start (``starts[1]``) over that of the
    cubic one (``starts[0]``), on the tip predictor's band around the crack tip ``a``
    (LATTICE_BAND_IN nodes inside, LATTICE_BAND_OUT outside), ``h`` the solved gap."""
    tip = np.searchsorted(r, a)
    e_cubic, e_tip = 0.0, 0.0
    for i in range(max(tip - LATTICE_BAND_IN, 0), min(tip + LATTICE_BAND_OUT, r.size)):
        e_cubic = max(e_cubic, abs(starts[0, i] - h[i]))
        e_tip = max(e_tip, abs(starts[1, i] - h[i]))
    if e_tip == 0.0 or e_cubic == 0.0:
        return 0.0
    return np.log2(e_tip / e_cubic)


@njit(cache=True, inline='always')
def predict(h, h_prev, h_prev2, dt, dt_prev, dt_prev2, hp):
    """Starting gap of the next solve: quadratic (Lagrange) extrapolation through the last
    three accepted states (linear after one, constant at the start), floored at
    PREDICT_FLOOR of the last gap. Returns True when the extrapolation was quadratic (its
    distance to the solution is then the step-error estimate)."""
    N = h.size
    if dt_prev2 > 0.0:
        t1 = -dt_prev
        t2 = -dt_prev - dt_prev2
        l0 = (dt - t1) * (dt - t2) / (t1 * t2)
        l1 = dt * (dt - t2) / (t1 * (t1 - t2))
        l2 = dt * (dt - t1) / (t2 * (t2 - t1))
        for i in range(N):
            hp[i] = max(l0 * h[i] + l1 * h_prev[i] + l2 * h_prev2[i], PREDICT_FLOOR * h[i])
        return True
    if dt_prev > 0.0:
        s = dt / dt_prev
        for i in range(N):
            hp[i] = max(h[i] + s * (h[i] - h_prev[i]), PREDICT_FLOOR * h[i])
        return False
    _copy(h, hp)
    return False


@njit(cache=True, inline='always')
def next_step(dd, easy, da, da_max, err, dd_max, step_tol):
    """Step control after an accepted step: (next indentation step, easy-step count).

    Up to ``dd_max`` the step doubles after EASY_STEPS steps in a row that moved the crack
    tip by less than EASY_DA_FRACTION da_max. Beyond it (up to SMOOTH_STEP_FACTOR dd_max)
    it doubles after EASY_STEPS steps in a row while a doubled step would keep the tip
    motion below SMOOTH_DA_FRACTION da_max and the predictor's load error ``err``, 8 err
    for a doubled step (third order), below ``step_tol``; it is halved back as soon as
    either bound is exceeded. Steps within STEP_RTOL of a bound are at the bound.
    """
    if dd > dd_max * (1.0 + STEP_RTOL):
        if da > SMOOTH_DA_FRACTION * da_max or err > step_tol:
            return max(0.5 * dd, dd_max), 0
        easy += 1
    elif da < EASY_DA_FRACTION * da_max:
        easy += 1
    else:
        easy = 0
    if easy >= EASY_STEPS:
        if dd < dd_max * (1.0 - STEP_RTOL):
            return min(2.0 * dd, dd_max), 0
        if (2.0 * da < SMOOTH_DA_FRACTION * da_max and 8.0 * err < step_tol
                and dd < SMOOTH_STEP_FACTOR * dd_max * (1.0 - STEP_RTOL)):
            return min(2.0 * dd, SMOOTH_STEP_FACTOR * dd_max), 0
    return dd, easy


# ------------------------------------------------------------------ the unloading loop

@njit(cache=True, inline='always')
def new_work(r, h_init, q):
    """The loop's arrays (:data:`Work`), the last four states all ``h_init``, the tip
    predictor's ring empty."""
    N = h_init.size
    M = q.shape[0]
    r2half = np.empty(N)
    for i in range(N):
        r2half[i] = 0.5 * r[i] ** 2
    return Work(h_init.copy(), h_init.copy(), h_init.copy(), h_init.copy(), np.empty(N),
                np.empty(N), np.empty(N), np.empty(N), np.empty(N), np.empty(M),
                np.empty(M), np.empty(N), np.empty(N), r2half, q,
                np.empty((LATTICE_HISTORY, N)), np.empty((2, LATTICE_HISTORY)),
                np.empty((2, N)), np.zeros(ZONE_SIZE), h_init.copy())


@njit(cache=True, inline='always')
def start_run(mesh, physics, start, records, work, run, hm):
    """The state the loop starts from: the tractions of ``work.h`` (the LJ law's at the
    relaxed start, at rest; a resumed run's own, ``start.sigma``) and the run's time,
    indentation and contact radius (record 0, the initial state, written for a new run).
    Returns (records written, index of the load minimum among them)."""
    h0, r = physics.h0, mesh.r
    if start.n == 0:
        lj_traction(work.h, h0, physics.c, work.sigma)
    else:
        _copy(start.sigma, work.sigma)
        if not np.isinf(physics.hdot_c) and start.step.size > 1 and start.step[1] > 0.0:
            _copy(start.h_prev, work.h_prev)
            run[RUN_DT_PREV] = start.step[1]
    run[RUN_A] = crossing_radius(work.h, r, hm)
    if start.n == 0:
        records.t[0] = 0.0
        records.delta[0] = start.delta0
        records.P[0] = load(work.sigma, mesh.wP, work.h, mesh.tail, h0, physics.c)
        records.a[0] = run[RUN_A]
        records.a_inner[0] = crossing_radius(work.h, r, h0)
        n = 1
    else:
        n = start.n
    run[RUN_T] = records.t[n - 1]
    run[RUN_DELTA] = records.delta[n - 1]
    if physics.compliance != 0.0:       # the machine's displacement D = delta + P/K
        run[RUN_DELTA] += physics.compliance * records.P[n - 1]
    i_min = 0
    for i in range(1, n):
        if records.P[i] < records.P[i_min]:
            i_min = i
    return n, i_min


@njit(cache=True, inline='always')
def zone_step(physics, work, dt, dt_prev):
    """The process zone's state over the step ``dt``: its opening rate by the variable-step
    BDF2 formula, hdot = [a0 h - a1 h_n + a2 h_(n-1)] / dt with w = dt/dt_prev, a0 = (1 +
    2w)/(1 + w), a1 = 1 + w, a2 = w^2/(1 + w) (second order; backward Euler, a0 = 1, on a
    first step), written as hdot = a0 (h - ref)/dt: ``work.ref`` and zone[ZONE_RATE] =
    a0/(hdot_c dt) (:func:`kernels.interface.traction`). Backward Euler's first-order lag
    moved the pull-off by 1 % at the balanced preset's step (docs/design.md)."""
    a0 = 1.0
    if dt_prev > 0.0:
        w = dt / dt_prev
        a0 = (1.0 + 2.0 * w) / (1.0 + w)
        a1 = 1.0 + w
        a2 = w * w / (1.0 + w)
        for i in range(work.h.size):
            work.ref[i] = (a1 * work.h[i] - a2 * work.h_prev[i]) / a0
    else:
        _copy(work.h, work.ref)
    work.zone[ZONE_RATE] = a0 / (physics.hdot_c * dt)
    work.zone[ZONE_XI] = physics.xi
    work.zone[ZONE_SMOOTH] = smoothing_rate(physics.xi)


@njit(cache=True, inline='always')
def predict_step(mesh, physics, work, run):
    """-- predict: the step's time step, C_eff, H and g (of the machine's displacement D, the
    indentation of a rigid machine) for the step ``run[RUN_DD]``, and
    Newton's starting gaps: the quadratic extrapolation in ``work.h_pred`` (and ``hp``),
    the cubic one, where four states exist, in ``work.hp``, replaced near the crack tip by
    the tip predictor's (:func:`predict_lattice`) where it applies and has been the nearer
    of the two on the last steps where both were made (LATTICE_SCORE_USE). Returns
    (quadratic, cubic): which extrapolations were made."""
    h0, dd = physics.h0, run[RUN_DD]
    dt = dd / (physics.rate * h0)
    run[RUN_DT] = dt
    run[RUN_CEFF] = step_coefficients(physics.weights, physics.times, dt, work.e, work.b)
    if not np.isinf(physics.hdot_c):
        zone_step(physics, work, dt, run[RUN_DT_PREV])
    history_vector(physics.weights, work.e, work.b, work.q, work.sigma, work.H)
    delta = run[RUN_DELTA]
    for i in range(work.g.size):
        work.g[i] = -(delta - dd) + h0 + work.r2half[i]
    quadratic = predict(work.h, work.h_prev, work.h_prev2, dt, run[RUN_DT_PREV],
                        run[RUN_DT_PREV2], work.hp)
    _copy(work.hp, work.h_pred)
    # Newton starts from the cubic extrapolation (where four states exist): on the
    # vs-numpy scenes its residual is several times smaller, and 1.2-1.8 Newton
    # iterations per step remain instead of 1.7-2.4; the quadratic one (h_pred) stays
    # the step-error estimate
    cubic = predict_cubic(work.h, work.h_prev, work.h_prev2, work.h_prev3, dt,
                          run[RUN_DT_PREV], run[RUN_DT_PREV2], run[RUN_DT_PREV3], work.hp)
    run[RUN_TIP_MADE] = 0.0
    if not np.isinf(physics.hdot_c) and not run[RUN_DT_PREV] > 0.0:
        # a process zone's first step: Newton starts from the rigid opening of the gaps in
        # tension (at rest the law's rate term vanishes, and a Jacobian made there misses the
        # far field's stiffness: the solve failed on n 0.5, k 0.1, mu 5, rate 10 with 414
        # factorizations); from rest again where that fails (the retry of a cubic start)
        for i in range(work.h.size):
            if work.h[i] > h0:
                work.hp[i] = work.h[i] + dd
        return quadratic, True
    if cubic:
        _copy(work.hp, work.starts[0])
        if predict_lattice(mesh.r, work.h, work.past, work.past_ta, int(run[RUN_PAST]), dt,
                           work.hp):
            run[RUN_TIP_MADE] = 1.0
            _copy(work.hp, work.starts[1])
            if not run[RUN_TIP_SCORE] < LATTICE_SCORE_USE:
                _copy(work.starts[0], work.hp)
    return quadratic, cubic


@njit(cache=True, inline='always')
def wall_step(h, dh, h0, wall):
    """The gap ``h`` after Newton's step ``dh``, for a node in the repulsive wall (h < h0)
    that the step opens taken in u = (h0/h)^``wall`` (Newton's linearization in u rather than
    in h: ``h (1 - wall dh/h)^(-1/wall)``, h0 where that is not finite), at most h0 and at
    least ``h + dh``; ``h + dh`` elsewhere and at ``wall`` 0.

    Deep in the wall the Lennard-Jones traction grows as h^-9, and Newton in h lengthens the
    gap by about h/9 an iteration: the residual falls by (1 + 1/9)^9, about 2.6, an
    iteration, some twenty from a start 1e6-1e8 tolerances off (the dwell's starts on the
    quarter-resolution mesh of the error estimate's crossing check). In u the wall is
    nearly linear. A compressed contact node's small step (dh << h/wall) is the same in
    both."""
    if wall > 0.0 and h < h0 and dh > 0.0:
        x = 1.0 - wall * dh / h
        opened = h * x ** (-1.0 / wall) if x > 0.0 else h0
        return max(h + dh, min(opened, h0))
    return h + dh


@njit(cache=True)
def settle_tip(h, g, A, ceff, H, law, lo, hi, iters, wall=0.0):
    """Newton on the gaps of the nodes [lo, hi) alone, the others held, for ``iters``
    iterations, in place: Newton's start settled at the crack tip, where the gap equation is
    most nonlinear and an extrapolated start is furthest off (the node behind an advancing
    tip lands on the repulsive wall: the protocol's approach, :mod:`kernels.protocol`; a
    process zone's rate term, :func:`solve_step`). Each iteration costs (hi - lo) rows of A,
    not all N. Keeps the start where the nodes' residual did not fall. Returns that
    residual's max, before and after.

    ``wall`` > 0: a node in the repulsive wall (h < h0) that Newton opens takes the step
    linearized in (h0/h)^wall rather than in h, ``h (1 - wall dh/h)^(-1/wall)``, at most to
    h0 (where the Lennard-Jones traction vanishes) and at least the step itself
    (:func:`wall_step`); 0: Newton's steps."""
    N, z = h.size, hi - lo
    sig, d, dr, w = np.empty(N), np.empty(N), np.empty(N), np.empty(N)
    traction(h, law.h_old, law.zone, law.h0, law.c, sig)
    for j in range(N):
        w[j] = ceff * sig[j] - H[j]
    kept = h[lo:hi].copy()
    J, piv, dz = np.empty((z, z)), np.empty(z, np.int32), np.empty((1, z))
    first, norm = np.inf, np.inf
    for it in range(iters + 1):
        traction_and_stiffness(h[lo:hi], law.h_old[lo:hi], law.zone, law.h0, law.c,
                               sig[lo:hi], d[lo:hi], dr[lo:hi])
        for k in range(lo, hi):
            w[k] = ceff * sig[k] - H[k]
        norm = 0.0
        for k in range(z):
            dz[0, k] = -(h[lo + k] - g[lo + k] - np.dot(A[lo + k], w))
            norm = max(norm, abs(dz[0, k]))
        first = norm if it == 0 else first
        if it == iters:
            break
        for k in range(z):
            for m in range(z):
                J[k, m] = -ceff * A[lo + k, lo + m] * d[lo + m]
            J[k, k] += 1.0
        if lu_factor(J, piv) != 0:
            break
        lu_solve(J, piv, dz)
        lam = positive_step(h[lo:hi], dz[0])
        for k in range(z):
            h[lo + k] = wall_step(h[lo + k], lam * dz[0, k], law.h0, wall)
    if not norm < first:
        for k in range(z):
            h[lo + k] = kept[k]
    return first, norm


@njit(cache=True)
def zone_ramp(hp, work, A, ceff, law, tol, max_iter, cache, stats, machine):
    """A process zone's first step by continuation in the zone's strength (ZONE_RAMP_START,
    ZONE_RAMP_FACTOR, ZONE_RAMP_SOLVES): Newton at the opening rate's scale
    ``work.zone[ZONE_RATE]`` times s, s rising from ZONE_RAMP_START to 1, each solve from the
    last one's state, the first from rest (``work.h``). True with the step's state in ``hp``;
    the scale is restored either way."""
    full = work.zone[ZONE_RATE]
    good = np.empty_like(hp)
    _copy(work.h, good)
    s_good, s = 0.0, ZONE_RAMP_START
    ok = False
    for _ in range(ZONE_RAMP_SOLVES):
        work.zone[ZONE_RATE] = s * full
        _copy(good, hp)
        cache[CACHE_STATE][STATE_VALID] = 0
        if newton_machine(hp, work.g, A, ceff, work.H, law, tol, max_iter, cache, stats,
                          machine):
            if s == 1.0:
                ok = True
                break
            _copy(hp, good)
            s_good, s = s, min(s * ZONE_RAMP_FACTOR, 1.0)
        elif s_good > 0.0 and s > s_good * 1.05:
            s = np.sqrt(s * s_good)
        elif s_good == 0.0 and s > 1e-12:
            s *= 1.0 / ZONE_RAMP_FACTOR
        else:
            break
        if past(cache[CACHE_DEADLINE][0]):
            break
    work.zone[ZONE_RATE] = full
    cache[CACHE_STATE][STATE_VALID] = 0
    return ok


@njit(cache=True, inline='always')
def solve_step(mesh, physics, control, work, run, cubic, hm, cache, stats):
    """-- solve: Newton from ``work.hp`` (with a process zone, its cubic start settled at
    the crack tip first: ZONE_SETTLE_NODES), again from the quadratic start where the cubic
    one failed; after a failure the step is halved, down to SNAP_STEP_FRACTION step_max, and
    the next solves are exact Newton; below it the path folds and the snapped state is
    looked for. A process zone's first step that finds none is tried once more at the step
    first tried by :func:`zone_ramp`. Returns SOLVED, HALVED, SNAPPED or FAILED (the state,
    if any, in hp)."""
    A, h0, hp = mesh.A, physics.h0, work.hp
    law = Interface(h0, physics.c, work.ref, work.zone)
    ceff, tol = run[RUN_CEFF], control.tol * h0
    max_iter = control.max_iter
    if not np.isinf(physics.hdot_c) and not run[RUN_DT_PREV] > 0.0:
        max_iter *= FIRST_ZONE_ITER
    machine = Machine(physics.compliance, mesh.wP, mesh.tail)
    if run[RUN_ZONE_RAMP] == 1.0 and not run[RUN_DT_PREV] > 0.0:
        run[RUN_ZONE_RAMP] = 2.0
        stats[STAT_FAILED_SOLVES] += 1
        if zone_ramp(hp, work, A, ceff, law, tol, max_iter, cache, stats, machine):
            cache[CACHE_STATE][STATE_EXACT] = 0
            return SOLVED
        return FAILED
    if not np.isinf(physics.hdot_c) and cubic and cache[CACHE_STATE][STATE_EXACT] == 0:
        tip = np.searchsorted(mesh.r, run[RUN_A])      # the last state's crack tip
        settle_tip(hp, work.g, A, ceff, work.H, law, max(tip - ZONE_SETTLE_NODES, 0),
                   min(tip + ZONE_SETTLE_NODES, hp.size), ZONE_SETTLE_ITER)
    ok = newton_machine(hp, work.g, A, ceff, work.H, law, tol, max_iter, cache, stats,
                        machine)
    if not ok and cubic:
        # where the path is not smooth (the tip jumping nodes on a coarse mesh) the
        # cubic start can overshoot: again from the quadratic one before the step halves
        stats[STAT_FAILED_SOLVES] += 1
        _copy(work.h_pred, hp)
        ok = newton_machine(hp, work.g, A, ceff, work.H, law, tol, max_iter, cache, stats,
                            machine)
    if ok:
        return SOLVED
    stats[STAT_FAILED_SOLVES] += 1
    state = cache[CACHE_STATE]
    state[STATE_VALID] = 0
    state[STATE_EXACT] = 1
    dd, dd_min = run[RUN_DD], control.step_min * h0
    if dd > max(dd_min, SNAP_STEP_FRACTION * (control.step_max * h0)) * (1.0 + STEP_RTOL):
        run[RUN_DD] = max(0.5 * dd, dd_min)
        return HALVED
    # the equilibrium path folds here (the crack tip snaps to the next node): look for the
    # snapped state by Newton from the profile shifted inward by 1..SNAP_MAX_SHIFT nodes,
    # else by pseudo-transient relaxation from the last state
    stats[STAT_JUMPS] += 1
    if snap(mesh, physics, work, ceff, tol, control.max_iter, hm, cache, stats):
        return SNAPPED
    _copy(work.h, hp)
    if relax_machine(hp, work.g, A, ceff, work.H, law, machine, tol, RELAX_MAX_ITER,
                     stats, cache[CACHE_DEADLINE][0]):
        return SNAPPED
    if (not np.isinf(physics.hdot_c) and not run[RUN_DT_PREV] > 0.0
            and run[RUN_ZONE_RAMP] == 0.0):
        # a process zone's first step that halving did not bring: again at the step first
        # tried (a lead-in's own, else the largest), by continuation in the zone's strength
        # (the smaller steps are the harder ones there: the law's rate term, 1/(hdot_c dt),
        # the stiffer)
        run[RUN_ZONE_RAMP] = 1.0
        run[RUN_DD] = (run[RUN_LEAD_STEP] if run[RUN_LEAD_STEP] > 0.0
                       else control.step_max * h0)
        return HALVED
    if run[RUN_LEAD_STEP] > 0.0 and dd > max(dd_min, SNAP_STEP_FRACTION
                                             * run[RUN_LEAD_STEP]) * (1.0 + STEP_RTOL):
        # a lead-in's step, already below the halving's floor (SNAP_STEP_FRACTION step_max):
        # halved, down to that fraction of the lead-in's own step
        run[RUN_DD] = max(0.5 * dd, dd_min)
        return HALVED
    return FAILED


@njit(cache=True, inline='always')
def near_pulloff(records, n, zone):
    """Whether the load minimum is near after record ``n - 1``: within the first two steps,
    where the load rose over the last step (at or past a minimum), or where the minimum
    predicted from the last three records (a Newton step on dP/dt = 0 with the load's slope
    and curvature in time: exact for a parabola) lies within a crack-tip travel of ``zone``
    (a_ref) at the tip's present speed."""
    if n < 3:
        return True         # the minimum may be the initial state (a contact starting at
                            # or beyond its pull-off): its crack speed is the first step's
    t0, t1, t2 = records.t[n - 3], records.t[n - 2], records.t[n - 1]
    if not (t0 < t1 < t2):
        return False
    s0 = (records.P[n - 2] - records.P[n - 3]) / (t1 - t0)
    s1 = (records.P[n - 1] - records.P[n - 2]) / (t2 - t1)
    if s1 >= 0.0:
        return True
    curvature = (s1 - s0) / (0.5 * (t2 - t0))
    speed = (records.a[n - 2] - records.a[n - 1]) / (t2 - t1)
    if curvature <= 0.0 or speed <= 0.0:
        return False
    # s1 is the slope half a step back: the minimum lies -s1/curvature after that instant
    return speed * (-s1 / curvature - 0.5 * (t2 - t1)) < zone


@njit(cache=True, inline='always')
def control_step(mesh, physics, control, work, run, hm, stats, da_max):
    """-- control the step: the crack tip (at the gap ``hm``) may move by ``da_max`` at most
    (a_ref); a step that moves it further is halved until the motion, assumed proportional
    to the step, is below REJECT_TARGET da_max (not below step_min). Returns (accepted, the
    new contact radius, its change)."""
    a_new = crossing_radius(work.hp, mesh.r, hm)
    da = abs(a_new - run[RUN_A])
    dd, dd_min = run[RUN_DD], control.step_min * physics.h0
    if da > da_max and dd > dd_min * (1.0 + STEP_RTOL):
        stats[STAT_REJECTED] += 1
        da_est = da
        while da_est > REJECT_TARGET * da_max and dd > dd_min:
            dd = max(0.5 * dd, dd_min)
            da_est *= 0.5
        run[RUN_DD] = dd
        return False, a_new, da
    return True, a_new, da


@njit(cache=True, inline='always')
def step_load(mesh, physics, work, quadratic):
    """The load of the solved state ``work.hp`` (its tractions into ``work.sig_new``) and the
    step-error estimate: the relative load error of the quadratic extrapolation, inf
    without one. Returns (P, err)."""
    h0, c, wP, tail = physics.h0, physics.c, mesh.wP, mesh.tail
    traction(work.hp, work.ref, work.zone, h0, c, work.sig_new)
    P = load(work.sig_new, wP, work.hp, tail, h0, c)
    if not quadratic:
        return P, np.inf
    traction(work.h_pred, work.ref, work.zone, h0, c, work.sigma_pred)
    return P, abs(load(work.sigma_pred, wP, work.h_pred, tail, h0, c) - P) / max(
        abs(P), LOAD_ERROR_FLOOR)


@njit(cache=True, inline='always')
def accept_step(mesh, physics, work, run, records, n, P, a_new):
    """-- accept: the Prony modes, the last four states and time steps move on by the
    solved state ``work.hp`` (also written to the tip predictor's ring, and the step's two
    starts compared on it), and record ``n`` (load ``P``, contact radius ``a_new``, the
    sphere's indentation D - P/K) is written."""
    update_modes(work.e, work.b, work.q, work.sig_new, work.sigma)
    dt = run[RUN_DT]
    _copy(work.h_prev2, work.h_prev3)
    _copy(work.h_prev, work.h_prev2)
    _copy(work.h, work.h_prev)
    _copy(work.hp, work.h)
    _copy(work.sig_new, work.sigma)
    run[RUN_DT_PREV3] = run[RUN_DT_PREV2]
    run[RUN_DT_PREV2] = run[RUN_DT_PREV]
    run[RUN_DT_PREV] = dt
    run[RUN_T] += dt
    run[RUN_DELTA] -= run[RUN_DD]
    run[RUN_A] = a_new
    records.t[n] = run[RUN_T]
    records.delta[n] = run[RUN_DELTA]
    if physics.compliance != 0.0:       # the sphere's indentation delta = D - P/K
        records.delta[n] -= physics.compliance * P
    records.P[n] = P
    records.a[n] = a_new
    records.a_inner[n] = crossing_radius(work.h, mesh.r, physics.h0)
    if run[RUN_TIP_MADE] != 0.0:
        run[RUN_TIP_SCORE] += LATTICE_SCORE_WEIGHT * (
            score_starts(mesh.r, work.starts, work.h, a_new) - run[RUN_TIP_SCORE])
    k = int(run[RUN_PAST]) % LATTICE_HISTORY
    _copy(work.h, work.past[k])
    work.past_ta[0, k] = run[RUN_T]
    work.past_ta[1, k] = a_new
    run[RUN_PAST] += 1


@njit(cache=True, inline='always')
def stop_status(mesh, control, records, n, i_min):
    """-- stop: after record ``n - 1``, the status that ends the run (the contact reached the
    mesh edge, the crack tip left the band, or :func:`stop_reached`), else STATUS_RUNNING."""
    a_new = records.a[n - 1]
    if a_new >= mesh.r[mesh.r.size - 1]:
        return STATUS_DOMAIN
    if a_new > control.tip_hi or a_new < control.tip_lo:
        return STATUS_LEFT_BAND
    if stop_reached(records.P, records.a, n, i_min, control.stop_mode, control.min_travel):
        return STATUS_DONE
    return STATUS_RUNNING


@njit(cache=True, inline='always')
def lead_step(run, step_max, da, da_max):
    """The next step of a lead-in (LEAD_GROWTH while the crack tip moved by less than
    EASY_DA_FRACTION ``da_max``), at most ``step_max`` (d_ref), into ``run[RUN_DD]`` and the
    halving's reference ``run[RUN_LEAD_STEP]``; whether the lead-in goes on."""
    dd = run[RUN_DD] * (LEAD_GROWTH if da < EASY_DA_FRACTION * da_max else 1.0)
    run[RUN_DD] = min(dd, step_max)
    lead = run[RUN_DD] < step_max
    run[RUN_LEAD_STEP] = run[RUN_DD] if lead else 0.0
    return lead


@njit(cache=True)
def unload(mesh, physics, control, start, records, cache, stats):
    """Unload at constant rate from the state ``start.h`` with the Prony recursion.

    Resumable: a run may be continued (in chunks of ``control.max_steps``, or on another
    mesh after the state arrays were carried over) by passing back its gap, modal state
    ``q``, step and records.

    Parameters (dimensionless, docs/design.md section 2; steps and tolerances in units of
    h0, converted to d_ref where used)
    ----------
    mesh : MeshArrays (A, r, wP, tail).
    physics : Physics (h0, c, weights, times, rate, hdot_c, xi, compliance).
    control : StepControl (step_max, step_min, da_max, step_tol, tol, max_iter, max_steps,
        stop_mode, min_travel, tip_lo, tip_hi, da_max_pulloff, pulloff_zone).
    start : RunState (h, delta0, q, n, step, sigma, h_prev); q, step, sigma, h_prev in/out.
    records : Records (t, delta, P, a, a_inner, h), written.
    cache : the Jacobian cache (:func:`new_jacobian_cache`): the initial solve's
        factorization, and the deadline (:func:`kernels.jacobian.set_deadline`).
    stats : int64 array of length N_STATS (incremented).

    Returns
    -------
    (status, n_records)
    """
    h0, hm = physics.h0, TIP_GAP * physics.h0
    work = new_work(mesh.r, start.h, start.q)
    run = np.zeros(N_RUN)
    n, i_min = start_run(mesh, physics, start, records, work, run, hm)
    run[RUN_DD] = start.step[0] * h0 if start.step[0] > 0.0 else control.step_max * h0
    lead = start.step.size > 2 and start.step[2] > 0.0
    run[RUN_LEAD_STEP] = run[RUN_DD] if lead else 0.0
    easy = 0
    status = STATUS_STEP_LIMIT
    while n <= control.max_steps:
        if past(cache[CACHE_DEADLINE][0]):
            status = STATUS_TIME_BUDGET
            break
        da_max = control.da_max
        if control.da_max_pulloff < da_max and near_pulloff(records, n, control.pulloff_zone):
            da_max = control.da_max_pulloff
        quadratic, cubic = predict_step(mesh, physics, work, run)
        outcome = solve_step(mesh, physics, control, work, run, cubic, hm, cache, stats)
        if outcome != SOLVED:
            easy = 0
            if outcome == HALVED:
                continue
            if outcome == FAILED:        # a solve the deadline cut short is no failure
                status = (STATUS_TIME_BUDGET if past(cache[CACHE_DEADLINE][0])
                          else STATUS_NEWTON_FAILED)
                break
            quadratic = False
        accepted, a_new, da = control_step(mesh, physics, control, work, run, hm, stats, da_max)
        if not accepted:
            easy = 0
            continue
        P, err = step_load(mesh, physics, work, quadratic)
        cache[CACHE_STATE][STATE_EXACT] = 0
        accept_step(mesh, physics, work, run, records, n, P, a_new)
        if P < records.P[i_min]:
            i_min = n
        n += 1
        stop = stop_status(mesh, control, records, n, i_min)
        if stop != STATUS_RUNNING:
            status = stop
            break
        if lead:
            lead = lead_step(run, control.step_max * h0, da, da_max)
        else:
            run[RUN_DD], easy = next_step(run[RUN_DD], easy, da, da_max, err,
                                          control.step_max * h0, control.step_tol * h0)
    _copy(work.h, records.h)
    _copy(work.sigma, start.sigma)
    _copy(work.h_prev, start.h_prev)
    if start.step.size > 1:
        start.step[1] = run[RUN_DT_PREV]
    if start.step.size > 2:
        start.step[2] = 1.0 if lead else 0.0
    start.step[0] = run[RUN_DD] / h0
    return status, n
