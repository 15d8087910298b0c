"""The test as run in the lab, on the BEM: approach to a preload, dwell, retract (issue 36).

A scene with a protocol (:class:`Protocol`) does not start relaxed at a0 or delta0. It starts
at first contact, just after the surfaces jumped into it: a jump-in is fast, so the bulk
answers it glassy. The start is the LJ equilibrium of the glassy compliance k = Chat(0) at
the indentation of the glassy JKR contact at zero load, with every Prony mode holding that
traction as a step applied at t = 0 (q_i = sigma: the hereditary integral of a step,
docs/design.md section 4), so that the material then relaxes from it (:func:`first_contact`).
Then

1. *approach*: the indentation grows at d delta/dt = approach_rate h0 (the unloading rate's
   units, docs/design.md section 2) until the load reaches the preload; the last step is cut
   so that it ends at the preload (a secant on its length, to PRELOAD_RTOL);
2. *dwell* for the time ``dwell`` (tau0), holding either the load at the preload (``hold``
   "force", the gap and the indentation of each step solved together,
   :func:`sweep.kernels.protocol.newton_at_load`, a secant on the indentation where that
   fails) or the indentation (``hold`` "depth"), with time steps growing by DWELL_GROWTH
   from the approach's last one;
3. *retract*: the unloading kernel (:func:`sweep.kernels.solve.unload`) continues from the
   dwell's last state, its Prony modes and records, at the scene's rate, to the pull-off (or
   separation), as every scene's unloading.

Phases 1 and 2 march the same hereditary integral as the kernel (the Prony recursion of
:mod:`sweep.kernels.history`, the Newton solve of :func:`sweep.kernels.solve.newton` on the
Lennard-Jones law), Newton starting from the unloading kernel's predictors settled at the
crack tip (:class:`_March`). Their steps run in compiled loops
(:func:`sweep.kernels.protocol.approach_steps`, :func:`sweep.kernels.protocol.dwell_steps`:
the same operations as :func:`_trial`'s and :func:`_dwell_step`'s Python, which take the
approach's first step, its cut to the preload and the rare step whose solve failed; Python's
glue had cost a fifth of a step). The rest is Newton's at the advancing crack
tip (docs/design.md, "The test protocol", for what it costs). A scene with a process zone
(``pz_law``) runs it too, every phase under the process zone's law, each step's opening rate
by backward Euler from the last state (:meth:`_March._equation`): the approach and the dwell
grow the contact and mostly close its crack, where the law is the Lennard-Jones law, but a
node may open (a glassy contact relaxing), and there the zone adds its traction as in the
retraction (the unloading kernel). The trajectory keeps every phase (``phase``: 0 approach, 1 dwell, 2 retraction); the row adds
the work the machine did on the sphere over the whole path, to the pull-off where the scene
stops there, ``hysteresis_energy`` (pi dg R d_ref, :func:`cycle_work`).
"""
from __future__ import annotations

import numpy as np

from ..kernels.history import history_vector, step_coefficients, update_modes
from ..kernels.interface import (ZONE_RATE, ZONE_SMOOTH, ZONE_XI, crossing_radius,
                                 lennard_jones, lj_traction, smoothing_rate, traction)
from ..kernels.jacobian import CACHE_DEADLINE, set_deadline, use_drift_scaled
from ..kernels.protocol import (CLOCK_A, CLOCK_DELTA, CLOCK_DT, CLOCK_DT_PREV, CLOCK_DT_PREV2,
                                CLOCK_GUESS, CLOCK_MADE, CLOCK_RING, CLOCK_SIZE, CLOCK_T,
                                CLOCK_P, CLOCK_PHASE, CLOCK_TIP_SCORE, APPROACH_PASSED,
                                DWELL_FAILED, ApproachControl, DwellControl,
                                DwellOut, MarchState, RECENT_DELTA, RECENT_DWELL, RECENT_T,
                                SETTLE_WALL_POWER,
                                approach_steps, dwell_steps, factorize_ahead, held_guess,
                                newton_at_load, predictor_steps)
from ..kernels.solve import (LATTICE_HISTORY, LATTICE_SCORE_USE, LATTICE_SCORE_WEIGHT,
                             Physics, invalidate, new_jacobian_cache, newton, predict,
                             predict_lattice, relax, score_starts, settle_tip)
from ..theory import jkr_contact_radius
from .postprocess import cycle_work
from ..scene import Protocol
from . import budget

__all__ = ["Protocol", "PHASES", "first_contact", "run_phases", "cycle_work"]

#: the phases' codes in the trajectory's ``phase`` array
PHASES = {"approach": 0, "dwell": 1, "retract": 2}
#: the approach ends when the load is within this fraction of the preload
PRELOAD_RTOL = 1e-6
#: the dwell's time steps grow by this factor from the approach's last one, after a step that
#: moved the contact radius by less than DWELL_GROW_BELOW ``da_max`` spacings ...
DWELL_GROWTH = 1.3
DWELL_GROW_BELOW = 0.5
#: ... starting no smaller than this fraction of the dwell, and halved no further than this one
DWELL_FIRST = 1e-4
DWELL_MIN_STEP = 1e-9
#: the dwell's predictors (the indentation held at force, Newton's start) extrapolate in
#: log(t - t_start + DWELL_LOG_SHIFT dwell) rather than in t
#: (:func:`sweep.kernels.protocol.dwell_clock`): the held contact creeps or relaxes about as a
#: power of the time since the hold began. Measured on the dwells at force of ``make
#: protocol-cost`` (the Python march, an instrumented Newton): the start's residual 150-230
#: -> 50-190 tolerances (median over the steps), Newton iterations a step 2.25 / 4.63 / 2.29
#: -> 1.75 / 3.66 / 1.80 on the three bench scenes and 3.17 / 3.08 -> 2.45 / 2.31 on the MPL
#: and SLS scenes at mu 5, the pull-offs within 2e-7; 1e-4 and 1e-5 did as well but on the
#: rate-1e4 bench scene (1.99 and 2.01, with steps of 10-37 iterations); the indentation's
#: guess alone on that clock 2.15 / 3.63 / 2.20, Newton's start alone no fewer
DWELL_LOG_SHIFT = 1e-3
#: the compiled dwell (:meth:`_March.compiled_dwell`) returns to Python, which checks the time
#: budget, after this many tries (a few milliseconds)
DWELL_CHUNK_STEPS = 32
#: a dwell at force solves its indentation to this fraction of the preload (the load of a
#: solve is known to about 1e-8 of it: Newton's tolerance is 1e-10 h0) ...
HOLD_RTOL = 1e-7
#: ... and accepts the nearest of its iterations within this fraction where the secant stalls
HOLD_ACCEPT = 1e-5
#: Newton's start is settled at the crack tip first, on this many nodes either side of it,
#: by this many Newton iterations on those nodes alone (:meth:`_March._settle`; 12 nodes,
#: against 8, made 11-32 % fewer factorizations on three of the four scenes of ``make
#: protocol-cost``, as many on the fourth; 16 and 24 no fewer, 32 more; 5 iterations no
#: fewer than 3, 1 more and 0 twice as many)
TIP_NODES = 12
TIP_ITER = 3
#: most Newton iterations of one solve, and secant iterations of a held step
MAX_ITER = 40
HOLD_ITER = 30
#: most Newton iterations of an approach step that may still be halved: those of the
#: unloading kernel's solves (``sweep.engine.bem.MAX_NEWTON_ITER``); a solve that needs more
#: is retried with half the step (halving from the largest, the approach's first step, from
#: the glassy contact, took 21, 21, 40, 17 and 19 iterations on trials all rejected)
TRIAL_ITER = 12
#: the approach's crack tip may move by this many times ``numerics.da_max`` spacings a step
#: (the dwell's and the retraction's: once). The pull-off is read on the retraction, from
#: the dwell's end; measured on the four scenes of ``make protocol-cost`` against 1: it moved
#: by 4e-9 to 3.6e-6 (error estimates 4.7e-4 to 2.7e-3), the contact radius after the dwell
#: by 5e-7 to 1.3e-5, the hysteresis energy by 1.5e-5 to 1.1e-4, with 26-34 % fewer
#: approach steps (4: more factorizations, no faster)
APPROACH_DA_FACTOR = 2.0
#: the dwell's crack tip may move by this many times ``numerics.da_max`` spacings a step. The
#: retraction's bound serves the crack speed read at its pull-off; the dwell reports none, and
#: its steps are what a protocol's cost over its relaxed start is made of where the held
#: contact creeps far (a glassy approach, then the dwell: ``make protocol-cost``'s two fast
#: bench scenes, where the dwell's crack travels 1.4-1.5 times the retraction's). Measured on the
#: seven scenes of ``make protocol-cost`` against references at band resolution 48 (balanced,
#: against 1): dwell steps 164 / 178 -> 61 / 65 and Newton iterations 289 / 445 -> 166 / 230 on
#: those two, their rows' walls 0.75 and 0.69 of before; every pull-off's error within its
#: row's estimate, by 2.9 to 12 times (errors 1.9e-5 / 5.5e-5 -> 8.2e-5 / 3.9e-5 there, the
#: estimates 2.4e-4 / 1.6e-4; the other five scenes' within 2e-5 of before). 2: walls 0.81
#: and 0.77; 4 and 6: no fewer steps, more iterations, errors 1.6e-4 and 1e-4
DWELL_DA_FACTOR = 3.0
#: the approach's Newton keeps its factorization with the crack-tip zone placed this many
#: nodes further out than the unloading's (:func:`sweep.kernels.protocol.factorize_ahead`:
#: 24 nodes inside the advancing tip, 48 outside), made again before a step whose start's
#: tip lies fewer than AHEAD_LEAST nodes inside the zone's outer end (the unloading's zone,
#: 24 nodes outside the tip, contracted Newton poorly, and was made again, once the tip had
#: advanced about 10 nodes: every 10-13 steps; measured on the four scenes of ``make
#: protocol-cost``: 3-7 % fewer Newton iterations over the whole run, 2-8 of 22-56
#: factorizations fewer)
AHEAD_NODES = 24
AHEAD_LEAST = 20
#: the approach's smallest step, as a fraction of the largest (then the fold is relaxed) ...
MIN_STEP_FRACTION = 1.0 / 64.0
#: ... by at most this many pseudo-transient iterations before Newton takes over, where
#: Newton from the JKR contact failed (:meth:`_March._jump`)
RELAX_ITER = 300


class _March:
    """The hereditary march of the approach and the dwell on one prepared problem: the state
    (gap, Prony modes, traction), the records, and one step's solve. Newton's start is the
    unloading kernel's: the quadratic extrapolation, replaced near the crack tip by the tip
    predictor's (:func:`sweep.kernels.solve.predict_lattice`, from a ring of the last
    accepted states) where that has been the nearer of the two on the last steps. Newton runs
    the drift-scaled chord (:func:`sweep.kernels.jacobian.scale_for_drift`): the pressed
    contact's interior stiffens at every step (docs/performance.md, "The protocol's march")."""

    def __init__(self, pb, h, delta, stats):
        self.pb, self.h, self.delta, self.t = pb, h, float(delta), 0.0
        N, M = h.size, pb.prony_weights.size
        self.sigma = np.empty(N)
        lj_traction(h, pb.h0, pb.c, self.sigma)
        self.q = np.repeat(self.sigma[None, :], M, axis=0)   # a step applied at t = 0
        self.h_prev, self.dt_prev = h.copy(), 0.0
        self.h_prev2, self.dt_prev2 = h.copy(), 0.0
        self.hold_slope = None      # dP/d delta of the last step held at force
        self.clock_origin = np.nan  # the dwell's predictors' clock (kernels.protocol.dwell_clock)
        self.advancing = False      # the crack tip advances: the approach
        self.law = self._new_law(N)
        self.cache, self.stats = new_jacobian_cache(N), stats
        use_drift_scaled(self.cache, True)      # the pressed contact stiffens every step
        self.records = {k: [] for k in ("t", "delta", "P", "a", "a_inner", "phase")}
        self.past, self.past_ta = np.empty((LATTICE_HISTORY, N)), np.empty((2, LATTICE_HISTORY))
        self.past_count, self.tip_score = 0, 0.0
        #: the most tries of one compiled chunk, and what moves the march's mesh with its
        #: crack tip between chunks (None: one mesh; :meth:`follow_tip`)
        self.chunk_steps, self.follow = DWELL_CHUNK_STEPS, None
        self._record(0)

    def _record(self, phase):
        pb, r = self.pb, self.pb.mesh.r
        for key, value in (("t", self.t), ("delta", self.delta),
                           ("P", pb.load(self.sigma, self.h)),
                           ("a", crossing_radius(self.h, r, pb.hm)),
                           ("a_inner", crossing_radius(self.h, r, pb.h0)), ("phase", phase)):
            self.records[key].append(value)
        k = self.past_count % LATTICE_HISTORY       # the tip predictor's ring
        self.past[k], self.past_ta[:, k] = self.h, (self.t, self.records["a"][-1])
        self.past_count += 1

    def recent(self):
        """The last three records' times, indentations and whether each was the dwell's, the
        newest last: the compiled march's ``recent`` (kernels.protocol.RECENT_*)."""
        rec, recent = self.records, np.zeros((3, 3))
        for j in range(1, min(3, len(rec["t"])) + 1):
            recent[[RECENT_T, RECENT_DELTA, RECENT_DWELL], 3 - j] = (
                rec["t"][-j], rec["delta"][-j], float(rec["phase"][-j] == PHASES["dwell"]))
        return recent

    @property
    def load(self) -> float:
        return self.records["P"][-1]

    def solve(self, delta, dt, fold=False, start=None, max_iter=MAX_ITER):
        """The state after a step to ``delta`` over ``dt`` (not accepted): (ok, h, sigma,
        P, e, b, starts), Newton from ``start`` (a gap) or else from the predictor
        (:meth:`_start`; ``starts`` its two starts where the tip predictor's was made, else
        None), at most ``max_iter`` iterations; where that fails and ``fold``, the stable
        state the pseudo-transient relaxation reaches from the last one (a dense
        factorization an iteration: for folds only)."""
        pb = self.pb
        e, b, ceff, H, g = self._equation(delta, dt)
        if start is not None:
            h, starts = start.copy(), None
        else:
            h, starts = self._start(dt)
            self._settle(h, g, ceff, H)
        self._ahead(h, ceff)
        ok = newton(h, g, pb.A, ceff, H, self.law, pb.numerics.tol * pb.h0, max_iter,
                    self.cache, self.stats)
        if not ok:
            invalidate(self.cache)
        if not ok and fold:
            h, ok = self._jump(delta, g, ceff, H)
        return self._state(ok, h, e, b, starts)

    def solve_at_load(self, delta, dt, force):
        """The state after the step ``dt`` whose load is ``force`` (to HOLD_RTOL), its
        indentation solved with the gap from the guess ``delta``
        (:func:`sweep.kernels.protocol.newton_at_load`): (indentation, :meth:`solve`'s
        tuple), or None where that did not converge."""
        pb = self.pb
        e, b, ceff, H, g = self._equation(delta, dt)
        h, starts = self._start(dt)
        self._settle(h, g, ceff, H)
        self._ahead(h, ceff)
        tols = np.array([pb.numerics.tol * pb.h0, HOLD_RTOL * force])
        ok, shift = newton_at_load(h, g, pb.mesh_arrays(), ceff, H, self.law, force, tols,
                                   MAX_ITER, self.cache, self.stats)
        if not ok:
            invalidate(self.cache)
            return None
        return delta + shift, self._state(True, h, e, b, starts)

    def _settle(self, h, g, ceff, H):
        """Newton's start ``h`` settled at the crack tip of the last state (TIP_NODES nodes
        either side, TIP_ITER iterations: :func:`sweep.kernels.solve.settle_tip`)."""
        tip = int(np.searchsorted(self.pb.mesh.r, self.records["a"][-1]))
        settle_tip(h, g, self.pb.A, ceff, H, self.law, max(tip - TIP_NODES, 0),
                   min(tip + TIP_NODES, h.size), TIP_ITER, SETTLE_WALL_POWER)

    def _ahead(self, h, ceff):
        """Where the crack tip advances (``advancing``), the factorization kept with its
        crack-tip zone ahead of the tip of ``h`` (AHEAD_NODES, AHEAD_LEAST:
        :func:`sweep.kernels.protocol.factorize_ahead`)."""
        if self.advancing:
            factorize_ahead(h, self.pb.A, ceff, self.law, AHEAD_NODES, AHEAD_LEAST, self.cache,
                            self.stats)

    def _new_law(self, N):
        """The march's interface on N nodes: the Lennard-Jones law, or the process zone's,
        whose opening rate each step sets (:meth:`_equation`)."""
        pb = self.pb
        law = lennard_jones(pb.h0, pb.c, N)
        if not np.isinf(pb.hdot_c):
            law.zone[ZONE_XI], law.zone[ZONE_SMOOTH] = pb.pz_xi, smoothing_rate(pb.pz_xi)
        return law

    def _equation(self, delta, dt):
        """The step's Prony coefficients e, b, C_eff, history H and gap g at ``delta``; with a
        process zone, the step's law set in ``law``: its opening rate from the last state
        over ``dt`` (backward Euler, as the unloading kernel's steps)."""
        pb = self.pb
        M, N = pb.prony_weights.size, self.h.size
        e, b, H = np.empty(M), np.empty(M), np.zeros(N)
        ceff = step_coefficients(pb.prony_weights, pb.prony_times, dt, e, b)
        history_vector(pb.prony_weights, e, b, self.q, self.sigma, H)
        if not np.isinf(pb.hdot_c):
            self.law.zone[ZONE_RATE] = 1.0 / (pb.hdot_c * dt)
            self.law.h_old[:] = self.h
        return e, b, ceff, H, -delta + pb.h0 + 0.5 * pb.mesh.r ** 2

    def _state(self, ok, h, e, b, starts):
        law, sig = self.law, np.empty(h.size)
        traction(h, law.h_old, law.zone, law.h0, law.c, sig)
        return ok, h, sig, self.pb.load(sig, h), e, b, starts

    def _start(self, dt):
        """Newton's start for the step ``dt`` and the two starts, quadratic and tip
        predictor's (None where the tip predictor made none)."""
        starts = np.empty((2, self.h.size))
        steps = predictor_steps(self.t, dt, self.dt_prev, self.dt_prev2, self.clock_origin)
        predict(self.h, self.h_prev, self.h_prev2, *steps, starts[0])
        starts[1] = starts[0]
        if not predict_lattice(self.pb.mesh.r, self.h, self.past, self.past_ta,
                               self.past_count, dt, starts[1]):
            return starts[0].copy(), None
        return starts[int(self.tip_score < LATTICE_SCORE_USE)].copy(), starts

    def _jump(self, delta, g, ceff, H):
        """The state across a fold of the path (the crack tip snapping along the contact):
        the pseudo-transient relaxation from the last state for RELAX_ITER iterations, and
        Newton from where they led where they did not converge (it crawls near the end of a
        jump)."""
        pb, tol = self.pb, self.pb.numerics.tol * self.pb.h0
        invalidate(self.cache)
        h = self.h.copy()
        if relax(h, g, pb.A, ceff, H, self.law, tol, RELAX_ITER, self.stats,
                 self.cache[CACHE_DEADLINE][0]):        # the scene's budget (it had run on)
            return h, True
        return h, newton(h, g, pb.A, ceff, H, self.law, tol, MAX_ITER, self.cache, self.stats)

    def accept(self, delta, dt, solved, phase):
        _, h, sig, _, e, b, starts = solved
        update_modes(e, b, self.q, sig, self.sigma)
        if starts is not None:
            a = crossing_radius(h, self.pb.mesh.r, self.pb.hm)
            self.tip_score += LATTICE_SCORE_WEIGHT * (
                score_starts(self.pb.mesh.r, starts, h, a) - self.tip_score)
        self.h_prev2, self.h_prev, self.h, self.sigma = self.h_prev, self.h, h, sig
        self.dt_prev2, self.dt_prev = self.dt_prev, dt
        self.delta, self.t = float(delta), self.t + dt
        self._record(phase)


    def follow_tip(self):
        """Before a chunk of steps: where the march runs on a window around its crack tip
        (``follow``, :class:`sweep.engine.tip_following.MarchWindow`), let it bound the
        chunk (``chunk_steps``) and move the window to the tip; else nothing."""
        if self.follow is not None:
            self.follow(self)

    def move_to(self, pb, h, q, sigma=None):
        """Go on on the mesh of the prepared problem ``pb`` from the state carried there
        (gap ``h``, Prony modes ``q``, with a process zone the traction ``sigma`` under the
        last step's law: :func:`sweep.engine.tip_following.transfer`). The records and the
        clock go on; the predictors start from the carried state (the last states, on the
        old mesh, are dropped), the Jacobian cache is new."""
        N = h.size
        self.pb, self.h, self.q = pb, h, np.ascontiguousarray(q)
        if sigma is None:
            sigma = np.empty(N)
            lj_traction(h, pb.h0, pb.c, sigma)
        self.sigma = sigma
        self.h_prev, self.h_prev2 = h.copy(), h.copy()
        self.law = self._new_law(N)
        self.cache = new_jacobian_cache(N)
        use_drift_scaled(self.cache, True)
        budget.arm(self.cache)
        self.past, self.past_ta = np.empty((LATTICE_HISTORY, N)), np.empty((2, LATTICE_HISTORY))
        self.past_count, self.tip_score = 0, 0.0

    def compiled_dwell(self, protocol: Protocol, end, dt, da_max, dt_min):
        """At most DWELL_CHUNK_STEPS tries of the dwell's steps to ``end`` from the step
        ``dt`` by the compiled march (:func:`sweep.kernels.protocol.dwell_steps`: what
        :func:`_dwell_step` does, to the last bit): (outcome, the next step, None; on
        DWELL_FAILED the step whose solve failed, and (its guessed indentation, the
        predictor's starts or None) for :func:`_dwell_step`)."""
        pb = self.pb
        control = DwellControl(
            pb.hm, protocol.hold != "depth", float(protocol.preload),
            np.array([pb.numerics.tol * pb.h0, HOLD_RTOL * protocol.preload]), float(end),
            float(da_max), float(dt_min), DWELL_GROWTH, DWELL_GROW_BELOW, TIP_NODES, TIP_ITER,
            MAX_ITER, self.chunk_steps, self.clock_origin)
        outcome, clock, out = self._compiled(dwell_steps, control, dt, PHASES["dwell"])
        failed = None
        if outcome == DWELL_FAILED:
            failed = (float(clock[CLOCK_GUESS]), out.starts if clock[CLOCK_MADE] else None)
        return outcome, float(clock[CLOCK_DT]), failed

    def compiled_approach(self, protocol: Protocol, dd, speed, dd_max, da_max):
        """At most DWELL_CHUNK_STEPS tries of the approach's steps from the indentation step
        ``dd`` by the compiled march (:func:`sweep.kernels.protocol.approach_steps`: what
        :func:`_approach` does with :func:`_trial`, to the last bit): (outcome, the next
        step, None; or where a step is handed over, its step and (the solved state as
        :meth:`solve` returns it, the contact radius's change) for :func:`_approach` to end:
        the step whose load passed the preload, and the smallest step whose solve failed,
        its fold relaxed here as :meth:`solve` does)."""
        pb = self.pb
        control = ApproachControl(
            pb.hm, float(protocol.preload), PRELOAD_RTOL, float(speed), float(dd_max),
            MIN_STEP_FRACTION * dd_max, float(da_max), pb.numerics.tol * pb.h0, TRIAL_ITER,
            MAX_ITER, TIP_NODES, TIP_ITER, AHEAD_NODES, AHEAD_LEAST, self.chunk_steps)
        outcome, clock, out = self._compiled(approach_steps, control, dd, PHASES["approach"])
        dd = float(clock[CLOCK_DT])
        if outcome not in (APPROACH_PASSED, DWELL_FAILED):
            return outcome, dd, None
        delta = float(clock[CLOCK_GUESS])
        e, b, ceff, H, g = self._equation(delta, dd / speed)
        starts = out.starts.copy() if clock[CLOCK_MADE] else None
        if outcome == APPROACH_PASSED:
            h, ok = out.h.copy(), True
        else:                   # the smallest step: relax the fold (solve's fold)
            h, ok = self._jump(delta, g, ceff, H)
        solved = self._state(ok, h, e, b, starts)
        moved = abs(crossing_radius(solved[1], pb.mesh.r, pb.hm) - self.records["a"][-1])
        return outcome, dd, (solved, moved)

    def _compiled(self, kernel, control, step, phase):
        """The compiled march's call: the state, counters and records carried in and out
        (the kernel's records appended with ``phase``); returns (outcome, clock, out)."""
        pb, N = self.pb, self.h.size
        rec = self.records
        clock = np.zeros(CLOCK_SIZE)
        clock[[CLOCK_T, CLOCK_DELTA, CLOCK_DT, CLOCK_DT_PREV, CLOCK_DT_PREV2, CLOCK_TIP_SCORE,
               CLOCK_RING, CLOCK_A, CLOCK_P, CLOCK_PHASE]] = (
            self.t, self.delta, step, self.dt_prev, self.dt_prev2, self.tip_score,
            self.past_count, rec["a"][-1], rec["P"][-1], float(phase == PHASES["dwell"]))
        state = MarchState(self.h, self.h_prev, self.h_prev2, self.q, self.sigma, self.past,
                           self.past_ta, clock, self.recent())
        out = DwellOut(np.empty((5, DWELL_CHUNK_STEPS)), np.empty((2, N)), np.empty(N),
                       np.empty(N))
        outcome, n = kernel(pb.mesh_arrays(),
                            Physics(pb.h0, pb.c, pb.prony_weights, pb.prony_times,
                                    pb.scene.rate, pb.hdot_c, pb.pz_xi),
                            self.law, control, state, out, self.cache, self.stats)
        for i, key in enumerate(("t", "delta", "P", "a", "a_inner")):
            rec[key].extend(float(x) for x in out.records[i, :n])
        rec["phase"].extend([phase] * n)
        self.t, self.delta = float(clock[CLOCK_T]), float(clock[CLOCK_DELTA])
        self.dt_prev, self.dt_prev2 = float(clock[CLOCK_DT_PREV]), float(clock[CLOCK_DT_PREV2])
        self.tip_score, self.past_count = float(clock[CLOCK_TIP_SCORE]), int(clock[CLOCK_RING])
        return outcome, clock, out


def _approach(m: _March, protocol: Protocol, compiled: bool = True) -> None:
    """Indentation steps of ``numerics.step`` h0 (halved where Newton fails or the contact
    radius moves by more than APPROACH_DA_FACTOR ``da_max`` spacings) until the load reaches
    the preload; the step that passes it is cut to end there. The first step is the one
    halving would give, found from below (:func:`_first_step`).

    The steps after the first are taken by the compiled march (:meth:`_March.compiled_approach`),
    which returns every DWELL_CHUNK_STEPS tries for the time budget and hands over the step
    whose load passed the preload (cut here) and the smallest step whose solve failed (its
    fold relaxed here); ``compiled`` False takes every step in Python (:func:`_trial`), the
    compiled one's reference."""
    pb = m.pb
    m.advancing = True
    speed = protocol.approach_rate * pb.h0
    dd_max = pb.numerics.step * pb.h0
    da_max = APPROACH_DA_FACTOR * pb.numerics.da_max * pb.mesh.spacing
    dd = None
    while m.load < protocol.preload * (1.0 - PRELOAD_RTOL):
        budget.check("the approach")
        m.follow_tip()
        if dd is None:
            dd, solved, moved = _first_step(m, speed, dd_max, da_max)
        elif compiled:
            outcome, dd, handed = m.compiled_approach(protocol, dd, speed=speed,
                                                      dd_max=dd_max, da_max=da_max)
            if handed is None:
                continue
            solved, moved = handed
        else:
            smallest = dd <= MIN_STEP_FRACTION * dd_max
            solved, moved, passed = _trial(m, dd, speed, smallest, da_max)
            if not passed and not smallest:
                dd = max(0.5 * dd, MIN_STEP_FRACTION * dd_max)
                continue
        if not solved[0]:
            raise RuntimeError(f"approach: no equilibrium at delta = {m.delta + dd:.6g}")
        if solved[3] > protocol.preload:
            dd, solved = _cut_to_preload(m, protocol, dd, speed, solved)
        m.accept(m.delta + dd, dd / speed, solved, PHASES["approach"])
        dd = min(2.0 * dd, dd_max) if moved < 0.5 * da_max else dd


def _trial(m: _March, dd, speed, smallest, da_max):
    """The approach's step ``dd`` tried (not accepted): (solved, the contact radius's change,
    passed: Newton converged, within TRIAL_ITER iterations unless ``smallest``, and the
    radius moved by at most ``da_max``). The smallest step may relax a fold
    (:meth:`_March.solve`)."""
    solved = m.solve(m.delta + dd, dd / speed, fold=smallest,
                     max_iter=MAX_ITER if smallest else TRIAL_ITER)
    moved = abs(crossing_radius(solved[1], m.pb.mesh.r, m.pb.hm) - m.records["a"][-1])
    return solved, moved, solved[0] and moved <= da_max


def _first_step(m: _March, speed, dd_max, da_max):
    """The approach's first step, from the glassy contact: (dd, solved, radius change). The
    contact relaxes fast there, so that halving from ``dd_max`` tried up to seven steps,
    each that failed costing TRIAL_ITER Newton iterations; the step is found from below
    instead, from MIN_STEP_FRACTION dd_max doubled while the doubled step passes
    (:func:`_trial`). Where passing is monotone in the step, that is the step halving
    accepts (the smallest one whether it passes or not); it is on the four scenes of
    ``make protocol-cost``, fine and coarse meshes."""
    dd = MIN_STEP_FRACTION * dd_max
    best = _trial(m, dd, speed, True, da_max)
    while best[2] and dd < dd_max:
        budget.check("the approach")
        trial = _trial(m, min(2.0 * dd, dd_max), speed, False, da_max)
        if not trial[2]:
            break
        dd, best = min(2.0 * dd, dd_max), trial
    return dd, best[0], best[1]


def _cut_to_preload(m: _March, protocol: Protocol, dd, speed, solved):
    """The step from the last state whose load is the preload: a secant on its length
    between 0 (the last state's load) and ``dd`` (``solved``, past the preload)."""
    lo, p_lo, hi, p_hi = 0.0, m.load, dd, solved[3]
    for _ in range(HOLD_ITER):
        if not p_hi > p_lo:
            break
        x = lo + (protocol.preload - p_lo) * (hi - lo) / (p_hi - p_lo)
        trial = m.solve(m.delta + x, x / speed)
        if not trial[0]:
            break
        if abs(trial[3] / protocol.preload - 1.0) <= PRELOAD_RTOL:
            return x, trial
        if trial[3] > protocol.preload:
            hi, p_hi, solved, dd = x, trial[3], trial, x
        else:
            lo, p_lo = x, trial[3]
    return dd, solved


def _dwell(m: _March, protocol: Protocol, compiled: bool = True) -> None:
    """Time steps from max(the approach's last, DWELL_FIRST dwell), growing by DWELL_GROWTH,
    the last cut to end at ``dwell``; at each the indentation held, or solved so that the
    load stays at the preload. A step whose solve fails, or whose contact radius moves by
    more than DWELL_DA_FACTOR ``da_max`` spacings (a contact creeping outward), is halved, down to
    DWELL_MIN_STEP of the dwell, where a fold of the path is relaxed.

    Newton's first start is the approach's last state, the second the linear extrapolation
    through it and the dwell's first: the approach's motion, extrapolated from its last steps
    (an indentation step over the approach's speed, 1e-6 to 1e-5 tau0 at the fast bench
    scenes' rates) over the dwell's first (DWELL_FIRST dwell), started Newton 1e6-1e7
    tolerances off, and its iteration diverged. Measured on ``make protocol-cost``'s rate-1e4
    bench scene: the held steps that fell back to the secant 3 -> 0 in the fine solve, 2 -> 0
    and 8 -> 6 in the error estimate's, Newton iterations of the dwells' solves 665 -> 525,
    the row 0.87-0.91 of its wall (two A/B runs), the pull-off within 5e-8; the other scenes'
    pull-offs within 3e-11.

    The steps are taken by the compiled march (:meth:`_March.compiled_dwell`), which
    returns every DWELL_CHUNK_STEPS tries for the time budget and hands a step whose solve
    failed to :func:`_dwell_step` (the held step's secant, the relaxation of a fold);
    ``compiled`` False takes every step with :func:`_dwell_step`, the same march in Python
    (the compiled one's reference: the same records to the last bit)."""
    if protocol.dwell <= 0.0:
        return
    m.advancing = False     # a creeping contact: no fewer iterations with the zone ahead
    da_max = DWELL_DA_FACTOR * m.pb.numerics.da_max * m.pb.mesh.spacing
    dt_min = DWELL_MIN_STEP * protocol.dwell
    dt = max(m.dt_prev, DWELL_FIRST * protocol.dwell)
    m.dt_prev = m.dt_prev2 = 0.0        # the first start: the approach's last state (below)
    end = m.t + protocol.dwell
    m.clock_origin = m.t - DWELL_LOG_SHIFT * protocol.dwell
    while m.t < end * (1.0 - 1e-12):
        budget.check("the dwell")
        m.follow_tip()
        if not compiled:
            dt = _dwell_step(m, protocol, min(dt, end - m.t), da_max, dt_min)
            continue
        outcome, dt, failed = m.compiled_dwell(protocol, end, dt, da_max, dt_min)
        if outcome == DWELL_FAILED:
            dt = _dwell_step(m, protocol, dt, da_max, dt_min, failed)


def _dwell_step(m: _March, protocol: Protocol, dt, da_max, dt_min, failed=None):
    """One try of the dwell's step ``dt`` in Python; returns the next step (halved where the
    try failed or moved the contact radius by more than ``da_max``). ``failed`` = (guessed
    indentation, the predictor's starts or None): the compiled march's solve of this step
    failed, and the try goes on from there (held at force: the secant of ordinary solves,
    :func:`_held_fallback`; held at depth, the smallest step: the fold's relaxation)."""
    smallest = dt <= dt_min
    if protocol.hold == "depth":
        delta = m.delta
        if failed is None:
            solved = m.solve(delta, dt, fold=smallest)
        else:
            e, b, ceff, H, g = m._equation(delta, dt)
            h, ok = m._jump(delta, g, ceff, H)
            solved = m._state(ok, h, e, b, failed[1])
    elif failed is None:
        delta, solved = _held_step(m, protocol.preload, dt, fold=smallest)
    else:
        delta, solved = _held_fallback(m, protocol.preload, dt, smallest, failed[0])
    moved = abs(crossing_radius(solved[1], m.pb.mesh.r, m.pb.hm) - m.records["a"][-1])
    if (not solved[0] or moved > da_max) and not smallest:
        return max(0.5 * dt, dt_min)
    if not solved[0]:
        raise RuntimeError(f"dwell: no equilibrium at t = {m.t + dt:.6g}")
    m.accept(delta, dt, solved, PHASES["dwell"])
    return dt * DWELL_GROWTH if moved < DWELL_GROW_BELOW * da_max else dt


def _held_step(m: _March, force: float, dt, fold=False):
    """The indentation at which the step ``dt`` ends at the load ``force`` and its state:
    the gap and the indentation solved together from the indentation the dwell's last steps
    extrapolate to (:func:`_held_guess`, :meth:`_March.solve_at_load`); where that does
    not converge, :func:`_held_fallback`."""
    d0 = _held_guess(m, dt)
    held = m.solve_at_load(d0, dt, force)
    if held is not None:
        return held
    return _held_fallback(m, force, dt, fold, d0)


def _held_fallback(m: _March, force: float, dt, fold, d0):
    """The held step ``dt`` where the gap and indentation solved together did not converge:
    a secant of ordinary solves from the guess ``d0``, the first slope the last held step's
    (else from a step of 1e-3 h0), each solve after the first starting from the one before
    (``fold``: :meth:`_March.solve`)."""
    s0 = m.solve(d0, dt, fold)
    if s0[0] and abs(s0[3] - force) <= HOLD_RTOL * force:
        return d0, s0
    if m.hold_slope is not None and s0[0]:      # the last held step's slope: one solve less
        d1 = d0 + (force - s0[3]) / m.hold_slope
    else:
        d1 = d0 + 1e-3 * m.pb.h0
    s1 = _solve_near(m, d1, dt, fold, s0)
    best = (abs(s0[3] - force), d0, s0)
    for _ in range(HOLD_ITER):
        if not (s0[0] and s1[0]):
            return d1, s1
        best = min(best, (abs(s1[3] - force), d1, s1), key=lambda x: x[0])
        if best[0] <= HOLD_RTOL * force:
            break
        slope = (s1[3] - s0[3]) / (d1 - d0)
        m.hold_slope = slope if slope > 0.0 else m.hold_slope
        step = (force - s1[3]) / slope if slope != 0.0 else 0.0
        if d1 + step == d1:              # as close as the indentation's rounding allows
            break
        d0, s0 = d1, s1
        d1 = d1 + step
        s1 = _solve_near(m, d1, dt, fold, s0)
    # the load of a solve is known to its slope times Newton's tolerance on the gap: where
    # that exceeds HOLD_ACCEPT (a small preload on a soft interface), the secant ends there
    # (n 0.4688, k 0.04818, mu 0.8455, preload 0.1677 with a process zone: two indentations
    # 1.1e-7 h0 apart, below Newton's 1e-6, gave the same state, 2.3e-5 of the preload off)
    resolution = abs(m.hold_slope or 0.0) * m.pb.numerics.tol * m.pb.h0
    if best[0] <= max(HOLD_ACCEPT * force, resolution):
        return best[1], best[2]
    raise RuntimeError(f"dwell at force: the load stayed at {best[2][3]:.8g}, not {force:.8g}")


def _solve_near(m: _March, delta, dt, fold, near):
    """:meth:`_March.solve` from the gap of the solved state ``near`` (the same step at a
    nearby indentation), else from the extrapolation of the last states."""
    if near[0]:
        solved = m.solve(delta, dt, start=near[1])
        if solved[0]:
            return solved
    return m.solve(delta, dt, fold)


def _held_guess(m: _March, dt) -> float:
    """The indentation the dwell at force is expected at after the step ``dt``: the
    quadratic extrapolation on the dwell's clock through its last three states (the dwell's
    start among them; linear through two, the last indentation at the dwell's first step):
    :func:`sweep.kernels.protocol.held_guess`, which the compiled dwell calls."""
    return float(held_guess(m.recent(), m.t + dt, m.clock_origin))


def first_contact(pb, stats):
    """(gap, indentation) at first contact: the LJ equilibrium of the glassy compliance k =
    Chat(0) at the indentation of the glassy JKR contact at zero load (the JKR solution of
    modulus 1/k: radii k^(1/3), indentations k^(2/3) times the relaxed ones), by Newton from
    that JKR gap (where Newton fails, after RELAX_ITER pseudo-transient iterations)."""
    from .initial import jkr_gap_guess     # lazy: sweep.engine.initial imports problem

    k = 1.0 - float(np.sum(pb.prony_weights))
    a_s, d_s = k ** (1.0 / 3.0), k ** (2.0 / 3.0)
    a = float(jkr_contact_radius(load=0.0))
    delta = d_s * (a * a - np.sqrt(2.0 * a))
    h = d_s * jkr_gap_guess(pb.mesh.r / a_s, delta / d_s, pb.h0 / d_s)
    N = h.size
    cache = new_jacobian_cache(N)
    budget.arm(cache)
    g = -delta + pb.h0 + 0.5 * pb.mesh.r ** 2
    law, tol, guess = lennard_jones(pb.h0, pb.c, N), pb.numerics.tol * pb.h0, h.copy()
    ok = newton(h, g, pb.A, k, np.zeros(N), law, tol, MAX_ITER, cache, stats)
    if not ok:
        # at large mu the JKR gap's crack tip lies too far off for Newton (the tip-following
        # mesh's window at mu 21.6, k 0.83; mu 12, k 1 at the fast preset): the
        # pseudo-transient relaxation from it first, as across a fold (_March._jump)
        h = guess
        invalidate(cache)
        ok = (relax(h, g, pb.A, k, np.zeros(N), law, tol, RELAX_ITER, stats,
                    cache[CACHE_DEADLINE][0])
              or newton(h, g, pb.A, k, np.zeros(N), law, tol, MAX_ITER, cache, stats))
    if not ok:
        budget.check("the protocol's first contact")
        raise RuntimeError(f"no glassy contact at first touch (delta = {delta:.4g})")
    return h, float(delta)


def run_phases(pb, protocol: Protocol, stats, compiled: bool = True, follow=None):
    """Approach and dwell on the prepared problem ``pb``, the solver's counters into
    ``stats`` (:data:`sweep.kernels.solve.N_STATS`): the march (:class:`_March`) whose state
    and records the retraction continues. ``compiled`` False: every step in Python
    (:func:`_approach`, :func:`_dwell`), the compiled march's reference. ``follow``: called
    with the march before each chunk of its steps, it may move the march to another mesh
    (:meth:`_March.move_to`; the tip-following mesh's window,
    :class:`sweep.engine.tip_following.MarchWindow`); the march's ``pb`` is then the last.

    The march's solves read the scene's deadline (:mod:`sweep.engine.budget`; Newton gives up
    past it, :func:`sweep.kernels.jacobian.set_deadline`), and a march that fails past it
    raises :class:`sweep.engine.budget.OverBudget`, not the failure."""
    h, delta = first_contact(pb, stats)
    m = _March(pb, h, delta, stats)
    m.follow = follow
    budget.arm(m.cache)
    try:
        _approach(m, protocol, compiled)
        _dwell(m, protocol, compiled)
    except budget.OverBudget:
        raise
    except RuntimeError:
        budget.check("the protocol's march")
        raise
    finally:
        set_deadline(m.cache, np.inf)
    return m
