r"""Elastic quasi-static pull-off across the Tabor range (mu from 0.01 to 100).

An elastic scene (``k = 1``) unloaded quasi-statically has no history: its states are the
equilibria of the Lennard-Jones interface on the elastic half-space, and its pull-off is the
largest tension along that branch. This module models only that (no time steps, no Prony
series): the branch is parametrized by the contact radius ``a`` (the max-tension radius,
where the gap is ``h_m = 3^(1/6) h0``, docs/design.md section 2) instead of the indentation, so
the folds of the displacement-controlled path are no obstacle, and

    pull_off = - min_a P(a)

is found by a scan of ``a`` (each solve warm-started from its neighbour) and a bounded Brent
refinement around the scan's minimum.

Units and conventions of docs/design.md section 2 (a, r in a_ref; gaps and delta in d_ref; P in
pi dg R; traction positive when compressive).

Equilibrium at fixed ``a``. Nodes ``r_i = a x_i`` on a fixed graded pattern ``x`` with a
node at ``x = 1`` (index ``m``); traction piecewise linear with the nodal values
``sigma(h_i)`` (overlapping hats). Unknowns: the gaps ``h_i`` (``i != m``) and ``delta``:

    h_i + delta - h0 - r_i^2 / 2 - sum_j A_ij sigma(h_j) = 0,   h_m = h_m(LJ) = 3^(1/6) h0,

solved by Newton with a backtracking line search. Because the nodes scale with ``a``, the
influence matrix is ``a`` times that of the pattern (assembled once per scene) and the
discretization error varies smoothly with ``a``, which the minimization needs.

Mesh pattern (:func:`node_pattern`): uniform spacing ``l0 / 16`` within ``5 l0`` of the
tip (``l0 = 1.693 / mu^2`` a_ref, the Persson-Brener process zone), then growing
geometrically by ``grading`` = 1.05 on both sides up to ``coarse`` = 0.01 (relative to a)
inside and ``coarse * max(1, x)`` outside; where l0/16 is coarser than that (mu below about
3) the mesh is ``coarse`` throughout. Measured: a geometric refinement right down to the tip
(l0/128 graded by 1.025) converges slowly (error ~ 3e-4 at mu = 3.24 and 100): collocation of
the hats loses the error cancellation of a uniform mesh; the uniform zone converges to about
3e-5 (mu = 100: 1.50019 here, 1.500208 at l0/32 over 10 l0, unchanged at l0/64 or grading
1.0125). The domain extends to the radius where the rigid-sphere gap from the tip, ``h_m + (r^2 - a^2)/2``,
reaches ``tail_gap * h0`` (so it grows with h0 = 1 / (pi^(2/3) mu) as mu -> 0). The LJ force
beyond the mesh is added in closed form for a rigid continuation of the gap,
``2 pi int_{h_e}^inf sigma(h) dh``.
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np

from ..kernels.influence import assemble_nodes, load_weights_nodes
from ..kernels.interface import TIP_GAP, lj_traction_and_stiffness

from .. import units
from ..errors import check_range
from ..scene import Numerics, Result
from ..theory import jkr_contact_radius, jkr_indentation, maugis_dugdale_pull_off, maugis_lambda
from . import budget
from .initial import jkr_gap_guess
from .postprocess import cycle_work
from .resolution import hysteresis_error, unresolved
from .problem import derive

#: the branch mesh's defaults: uniform elements of l0 / ZONE_RESOLUTION at the tip, growing to
#: COARSE a (see the module docstring)
ZONE_RESOLUTION = 16.0
COARSE = 0.01
#: Persson-Brener process zone l0 * mu^2 in a_ref (docs/design.md section 2)
PROCESS_ZONE = 243.0 / (256.0 * math.pi * (math.pi / 9.0) ** 2) / math.pi ** (1.0 / 3.0)
#: contact radius at the JKR (force-controlled) pull-off, a_ref
A_JKR = (3.0 * math.sqrt(2.0) / 4.0) ** (2.0 / 3.0)


# ------------------------------------------------------------------------------ the mesh
def node_pattern(tip: float, zone_spacing: float, zone: float, coarse: float, x_out: float,
                 grading: float = 1.025):
    """Graded nodes x on [0, x_out] with a node at x = 1 (the tip), returned with its index.

    Spacing ``tip`` at x = 1, times ``grading`` per element away from it on both sides, capped
    at ``zone_spacing`` within ``zone`` of the tip, then at ``coarse`` inside and at
    ``coarse * x`` outside (all lengths relative to a).
    """
    def cap(x):
        far = coarse * max(1.0, x)
        return zone_spacing if abs(x - 1.0) < zone and zone_spacing < far else far

    inner = [1.0]
    ds = tip
    while True:
        nxt = inner[-1] - ds
        if nxt <= 0.5 * ds:
            break
        inner.append(nxt)
        ds = min(ds * grading, cap(nxt))
    inner.append(0.0)       # the last element lies between 0.5 and 1.5 times its neighbour
    outer = []
    x = 1.0
    ds = tip
    while x < x_out:
        x += ds
        outer.append(x)
        ds = min(ds * grading, cap(x))
    return np.array(inner[::-1] + outer), len(inner) - 1


@dataclass
class ElasticPullOff:
    """Elastic quasi-static pull-off of one scene (units of docs/design.md section 2)."""

    mu: float
    pull_off: float          # -min P, pi dg R
    a: float                 # max-tension radius at pull-off, a_ref
    delta: float             # indentation at pull-off, d_ref
    nodes: int
    solves: int
    newton_iterations: int
    seconds: float
    converged: bool
    reason: str = ""
    #: the scanned branch, a decreasing: radii (a_ref), loads (pi dg R), indentations (d_ref)
    branch: tuple | None = None
    #: d delta / d a at the pull-off (d_ref / a_ref), central difference on the branch
    ddelta_da: float = float("nan")
    #: fine spacing at the tip and mesh radius at the pull-off (a_ref)
    spacing: float = float("nan")
    domain: float = float("nan")


class ElasticBranch:
    """The elastic LJ equilibria of one mu, parametrized by the max-tension radius a.

    Parameters
    ----------
    mu : float
        Tabor parameter, in [0.01, 100].
    a_scale : float
        Radius (a_ref) the tip spacing is sized for (the expected pull-off radius).
    a_min : float
        Smallest radius the branch will be solved at (sizes the domain).
    zone_resolution, zone : float
        Uniform elements of l0 / zone_resolution within ``zone`` l0 of the tip (at
        a = a_scale), when that is finer than ``coarse``; graded outside.
    coarse : float
        Largest element, relative to a.
    tail_gap : float
        Domain edge where the rigid gap is this many h0.
    grading : float
        Growth ratio of neighbouring elements.
    domain : float or None
        Mesh radius at a = a_scale (a_ref) instead of the tail_gap rule (for comparisons).
    tail : bool
        Add the LJ force beyond the mesh (rigid continuation of the gap).
    """

    def __init__(self, mu, a_scale, a_min, zone_resolution=ZONE_RESOLUTION, zone=5.0, coarse=COARSE,
                 tail_gap=40.0, grading=1.05, domain=None, tail=True, tol=1e-10):
        self.mu = check_range("mu", mu, lo=0.01, hi=100.0)
        self.h0 = units.h0_hat(self.mu)
        self.c = units.lj_prefactor(self.mu)
        self.hm = TIP_GAP * self.h0
        l0 = PROCESS_ZONE / self.mu**2
        zone_spacing = min(l0 / zone_resolution, coarse * a_scale) / a_scale
        if zone_spacing >= coarse:      # l0 is no finer than the coarse mesh: no zone
            zone = 0.0
        if domain is None:
            x_out = max(math.sqrt(1.0 + 2.0 * (tail_gap - TIP_GAP) * self.h0 / a_min**2), 1.5)
        else:
            x_out = domain / a_scale
        self.x, self.m = node_pattern(zone_spacing, zone_spacing, zone * l0 / a_scale, coarse, x_out,
                                      grading)
        self.tail = tail
        self.A = assemble_nodes(self.x)
        self.w = load_weights_nodes(self.x)
        self.tol = tol
        self.iterations = 0
        self.solves = 0
        self._sig = np.empty(self.x.size)
        self._dsig = np.empty(self.x.size)

    @property
    def nodes(self) -> int:
        return int(self.x.size)

    def guess(self, a: float):
        """Starting gaps at radius a: the JKR gap for mu >= 1, the rigid sphere below."""
        r = a * self.x
        if self.mu >= 1.0:
            d = float(jkr_indentation(a))
            h = jkr_gap_guess(r, d, self.h0)
        else:
            h = np.maximum(self.hm + 0.5 * (r**2 - a * a), self.h0)
        h[self.m] = self.hm
        delta = self.hm - self.h0 - 0.5 * a * a
        return h, delta

    def residual(self, a, h, delta):
        lj_traction_and_stiffness(h, self.h0, self.c, self._sig, self._dsig)
        r = a * self.x
        return h + delta - self.h0 - 0.5 * r**2 - a * (self.A @ self._sig)

    def solve(self, a, h, delta, max_iter=60):
        """Newton for (h, delta) at radius a from the guess; returns (h, delta, ok)."""
        h = h.copy()
        h[self.m] = self.hm
        F = self.residual(a, h, delta)
        norm = np.max(np.abs(F))
        self.solves += 1
        for _ in range(max_iter):
            if norm < self.tol * self.h0:
                return h, delta, True
            self.iterations += 1
            J = -a * self.A * self._dsig[None, :]
            J[np.diag_indices_from(J)] += 1.0
            J[:, self.m] = 1.0
            step = np.linalg.solve(J, -F)
            dh = step.copy()
            dh[self.m] = 0.0
            dd = step[self.m]
            # keep every gap positive: at most a 70 % decrease per step
            shrink = np.where(dh < 0.0, -0.7 * h / np.minimum(dh, -1e-300), np.inf)
            t = min(1.0, float(np.min(shrink)))
            for _ in range(40):
                h_new = h + t * dh
                F_new = self.residual(a, h_new, delta + t * dd)
                n_new = np.max(np.abs(F_new))
                if n_new < (1.0 - 1e-4 * t) * norm or n_new < self.tol * self.h0:
                    break
                t *= 0.5
            else:
                return h, delta, False
            h, delta, F, norm = h_new, delta + t * dd, F_new, n_new
        ok = norm < self.tol * self.h0
        if ok:
            self.residual(a, h, delta)
        return h, delta, ok

    def load(self, a, h):
        """P = 2 pi (a^2 sum w_j sigma_j + the rigid-continuation tail beyond the mesh)."""
        sig = np.empty(h.size)
        lj_traction_and_stiffness(h, self.h0, self.c, sig, np.empty(h.size))
        x_end = 2.0 * self.x[-1] - self.x[-2]
        h_end = h[-1] + 0.5 * a * a * (x_end**2 - self.x[-1] ** 2)
        # kernels.interface.tail_load's formula, written in this order since before the BEM had
        # it (its results stay bitwise those computed then)
        q = self.h0 / h_end
        tail = -self.c * self.h0 * (0.5 * q**2 - 0.125 * q**8) if self.tail else 0.0
        return 2.0 * math.pi * (a * a * float(self.w @ sig) + tail)


def state_at(br: ElasticBranch, a0: float):
    """The branch's equilibrium at the radius ``a0``: (gap h, indentation delta, below),
    ``below`` whether a0 lies below the branch's displacement-controlled fold (the
    indentation decreases as the radius grows there: JKR's a < 0.5, where the state exists
    but no relaxed contact can be held under fixed grips); None where it was not found. From
    the branch's guess at a0, else along the branch from a radius where the guess is good
    (a small a0)."""
    h, d = br.guess(a0)
    h, d, ok = br.solve(a0, h, d)
    if not ok:
        h, d = br.guess(max(1.2, 2.0 * a0))
        for a in np.geomspace(max(1.2, 2.0 * a0), a0, 16):
            h, d, ok = br.solve(a, h, d)
            if not ok:
                return None
    _, d_up, ok_up = br.solve(1.001 * a0, h, d)
    return h, d, bool(ok_up and d_up < d)


def fold_refusal(mu: float, a0: float) -> str:
    """The reason of a scene refused because its a0 lies below the fold (:func:`state_at`);
    a physical refusal (:data:`sweep.errors.PHYSICAL_REFUSALS`)."""
    return (f"no stable contact of radius a0 = {a0:g}: it lies below the fold of the relaxed "
            f"elastic branch at mu = {mu:g} (the indentation decreases as the radius grows); "
            f"give a larger a0 (JKR: a0 > 0.5) or delta0")


def pull_off_radius_guess(mu: float) -> float:
    """Expected pull-off radius: JKR's 1.040 at high mu, the rigid DMT sphere's
    sqrt(2 (h_m - h0)) (gap h0 at the centre) at low mu; the larger of the two."""
    h0 = units.h0_hat(mu)
    return max(A_JKR, math.sqrt(2.0 * (TIP_GAP - 1.0) * h0))


def walk(br: ElasticBranch, radii):
    """The branch's states along ``radii``, each solve started from the last (the first from
    the branch's guess): ([(h, delta)], [load], None), or the radius whose solve failed last,
    the lists stopping before it."""
    h, delta = br.guess(radii[0])
    states, loads = [], []
    for a in radii:
        h, delta, ok = br.solve(a, h, delta)
        if not ok:
            return states, loads, a
        states.append((h, delta))
        loads.append(br.load(a, h))
    return states, loads, None


def elastic_pull_off(mu, span=(0.35, 2.5), scan=14, xtol=1e-5, a_start=None,
                     **mesh) -> ElasticPullOff:
    """Elastic quasi-static pull-off at Tabor parameter mu (see the module docstring).

    Parameters
    ----------
    mu : float
        Tabor parameter in [0.01, 100].
    **mesh
        Mesh and domain options of :class:`ElasticBranch` (zone_resolution, zone, coarse,
        tail_gap, grading, domain, tail).
    span : (float, float)
        Scanned radii relative to :func:`pull_off_radius_guess`.
    scan : int
        Radii in the scan (geometric, from the largest down).
    xtol : float
        Brent tolerance on a (relative to the guess).
    a_start : float, optional
        Unload from this contact radius: the branch is scanned from a_start down and the
        pull-off is the largest tension at radii <= a_start (the start itself if the load
        only rises from there).

    Returns
    -------
    ElasticPullOff
        ``converged`` is False (with the reason) if a solve failed or the minimum sits at an
        end of the scanned span.
    """
    t0 = time.perf_counter()
    mu = check_range("mu", mu, lo=ELASTIC_MU_RANGE[0], hi=ELASTIC_MU_RANGE[1])
    a_g = pull_off_radius_guess(mu)
    a_lo, a_hi = span[0] * a_g, span[1] * a_g
    br = ElasticBranch(mu, a_g, a_lo, **mesh)
    if a_start is None:
        radii = np.geomspace(a_hi, a_lo, scan)
    else:
        a_start = check_range("a_start", a_start, lo=0.0, lo_open=True)
        a_lo = min(a_lo, 0.5 * a_start)
        count = max(scan, int(math.ceil(scan * math.log(a_start / a_lo) / math.log(a_hi / a_lo))))
        radii = np.geomspace(a_start, a_lo, count)
    states, loads, failed_at = walk(br, radii)
    if failed_at is not None:
        return _failed(br, mu, t0, f"Newton did not converge at a = {failed_at:.4g}")
    branch = (radii, np.array(loads), np.array([d for _, d in states]))
    i = int(np.argmin(loads))
    if i == len(radii) - 1 or (i == 0 and a_start is None):
        return _failed(br, mu, t0, f"minimum of P(a) at the end of the scan (a = {radii[i]:.4g})")
    if i == 0:      # unloading from a_start: the tension only decreases from the start
        return ElasticPullOff(mu=mu, pull_off=-loads[0], a=float(radii[0]),
                              delta=float(states[0][1]), nodes=br.nodes, solves=br.solves,
                              newton_iterations=br.iterations,
                              seconds=time.perf_counter() - t0, converged=True,
                              reason="largest tension at the start", branch=branch,
                              spacing=float(radii[0] * (br.x[br.m + 1] - 1.0)),
                              domain=float(radii[0] * br.x[-1]))
    cache = {}

    from scipy.optimize import minimize_scalar  # lazy: not on a BEM scene's path

    def neg_pull(a):
        j = int(np.argmin(np.abs(radii - a)))
        h_s, d_s = states[j]
        h_a, d_a, ok = br.solve(a, h_s, d_s)
        if not ok:
            raise RuntimeError(f"Newton did not converge at a = {a:.4g}")
        cache[a] = (h_a, d_a)
        return br.load(a, h_a)

    try:
        res = minimize_scalar(neg_pull, bounds=(radii[i + 1], radii[i - 1]), method="bounded",
                              options={"xatol": xtol * a_g})
    except RuntimeError as err:
        return _failed(br, mu, t0, str(err))
    a_star = float(res.x)
    P = float(res.fun)
    h_star, d_star = cache[a_star]
    eps = 1e-4 * a_star
    d_pm = []
    for a in (a_star + eps, a_star - eps):
        _, d, ok = br.solve(a, h_star, d_star)
        d_pm.append(d if ok else float("nan"))
    return ElasticPullOff(mu=mu, pull_off=-P, a=a_star, delta=float(d_star), nodes=br.nodes,
                          solves=br.solves, newton_iterations=br.iterations,
                          seconds=time.perf_counter() - t0, converged=True, branch=branch,
                          ddelta_da=(d_pm[0] - d_pm[1]) / (2.0 * eps),
                          spacing=float(a_star * (br.x[br.m + 1] - 1.0)),
                          domain=float(a_star * br.x[-1]))


def _failed(br, mu, t0, reason) -> ElasticPullOff:
    return ElasticPullOff(mu=mu, pull_off=float("nan"), a=float("nan"), delta=float("nan"),
                          nodes=br.nodes, solves=br.solves, newton_iterations=br.iterations,
                          seconds=time.perf_counter() - t0, converged=False, reason=reason)


#: Tabor parameters of the elastic pull-off table (:func:`pull_off_table`)
TABLE_MU = (0.01, 0.03, 0.1, 0.3, 1.0, 3.24, 10.0, 30.0, 100.0)


def pull_off_table(mus=TABLE_MU, **options) -> list[dict]:
    """Elastic pull-off against mu with the Maugis-Dugdale guide (lambda = 1.157 mu).

    Rows: mu, pull_off, a, delta, nodes, seconds, converged, md_pull_off (the MD value at
    the equivalent lambda, :func:`sweep.theory.maugis_dugdale_pull_off`).
    """
    rows = []
    for mu in mus:
        r = elastic_pull_off(mu, **options)
        rows.append({"mu": mu, "pull_off": r.pull_off, "a": r.a, "delta": r.delta,
                     "nodes": r.nodes, "seconds": r.seconds, "converged": r.converged,
                     "md_pull_off": maugis_dugdale_pull_off(maugis_lambda(mu))[0]})
    return rows


if __name__ == "__main__":      # python -m sweep.engine.quasistatic: the table of the issue
    print(f"{'mu':>6} {'pull_off':>9} {'(P-1.5)mu':>9} {'a':>7} {'delta':>8} {'nodes':>5} "
          f"{'s':>6} {'MD':>7}")
    for row in pull_off_table():
        print(f"{row['mu']:6.2f} {row['pull_off']:9.5f} {(row['pull_off'] - 1.5) * row['mu']:9.4f} "
              f"{row['a']:7.4f} {row['delta']:8.4f} {row['nodes']:5d} {row['seconds']:6.2f} "
              f"{row['md_pull_off']:7.4f}")


def simulate_elastic(scene, numerics=None):
    """An elastic scene (k = 1) as a :class:`sweep.scene.Result`, by :func:`elastic_pull_off`.

    The quasi-static branch from the initial radius ``scene.a0`` (``delta0`` scenes are
    refused: give a0); the rate only sets the time axis, ``t = (delta0 - delta) / (rate h0)``,
    and the crack speed at pull-off, ``v_a = rate h0 / (d delta / d a)``. The trajectory is
    the scanned branch up to the displacement-controlled fold (smallest delta); ``a_inner``
    is not computed (NaN). Not handled: a load minimum beyond the fold (not met from mu =
    0.01 to 100: the fold lies at smaller radii). Counters:
    ``steps`` = equilibrium solves, ``factorizations`` = Newton iterations (one dense solve
    each). A numerical failure gives ``status="failed"`` with the reason, never raises.

    A compliant machine (``machine_stiffness`` K) holds an elastic sphere on the same
    branch, which depends on delta alone, stably up to the load minimum (dP/ddelta > 0 > -K
    there): the pull-off and the radius at it are the rigid machine's, and so is the crack
    speed, for the sphere moves at the machine's rate where dP/dt = 0. Only the clock
    differs: the machine's displacement D = delta + P/K falls at rate h0, t = (D0 - D) /
    (rate h0); the records' ``delta`` is the sphere's. A start below the pull-off radius is
    the load minimum itself (no crack speed, as with a rigid machine); where its load falls
    faster than K per unit indentation (dP/ddelta < -K) the spring cannot hold it, and the
    row fails with that reason.

    A scene with a test protocol (approach, dwell, retract) runs on the branch too
    (:func:`_protocol_start`): an elastic bulk has no memory, so the approach follows the
    branch from first contact up to the preload, the dwell (held at force or at depth) changes
    nothing, and the retraction is the branch's unloading from the preload's radius.

    The branch's resolution follows the numerics: the tip zone's spacing l0 /
    (``ZONE_RESOLUTION`` s) and the coarse spacing ``COARSE`` / s, s = ``band_resolution`` /
    ``ZONE_RESOLUTION`` and at least 1 (1 at the fast and balanced presets); where the
    estimate exceeds ``pull_off_rtol`` and ``numerics.refinements`` allows, it solves again
    with s times f = 1.2 sqrt(estimate / tolerance), f in [sqrt 2, 2] (``refinements``,
    ``band_resolution_used`` record it), within ``max_nodes`` and the scene's time budget.
    """
    if numerics is None:
        numerics = Numerics.preset("balanced")
    t0 = time.perf_counter()
    # never coarser than the default (at fast's 9 spacings per l0 the error grew 14-fold, to
    # 8e-4 at mu 3.24, and the estimate to 1.9e-2: the branch costs a fraction of a second)
    scale = max(numerics.band_resolution / ZONE_RESOLUTION, 1.0)
    t_solve = time.perf_counter()
    res = _simulate_elastic(scene, numerics, scale)
    res.band_resolution_used = ZONE_RESOLUTION * scale
    done = 0
    while done < numerics.refinements and unresolved(res) and math.isfinite(res.error_estimate):
        f = min(max(1.2 * math.sqrt(res.error_estimate / numerics.pull_off_rtol),
                    math.sqrt(2.0)), 2.0)
        # its dense solves grow as the cube of the nodes: the next one costs about f^3 times
        # the last, which must fit the nodes and the scene's budget (the branch's solves do
        # not read the deadline: a refinement begun before it ran 28.7 s on a 9 s budget)
        cost = (time.perf_counter() - t_solve) * f ** 3
        if res.nodes_used * f > numerics.max_nodes:
            res.reason += (f"; not refined further: the branch would need about "
                           f"{int(res.nodes_used * f)} nodes, above max_nodes = "
                           f"{numerics.max_nodes}")
            break
        if cost > budget.remaining():
            res.reason += (f"; not refined further: the time budget is spent (the next "
                           f"solve, about {cost:.2g} s, does not fit what is left of it)")
            break
        t_solve = time.perf_counter()
        finer = _simulate_elastic(scene, numerics, scale * f)
        done += 1
        if not (finer.ok or unresolved(finer)):      # the unresolved row stands
            res.reason += (f"; refined to {ZONE_RESOLUTION * scale * f:.3g} spacings per "
                           f"l0: {finer.reason}")
            break
        scale *= f
        res = finer
        res.band_resolution_used = ZONE_RESOLUTION * scale
    if done and res.ok:
        note = (f"refined {done} time{'s' * (done > 1)} to {ZONE_RESOLUTION * scale:.3g} "
                f"spacings per l0")
        res.reason = f"{res.reason}; {note}" if res.reason else note
    res.refinements = done
    res.wall_s = time.perf_counter() - t0
    return res


def _simulate_elastic(scene, numerics, scale: float):
    """:func:`simulate_elastic` at the resolution ``scale`` times the branch's default."""
    mesh = {"zone_resolution": ZONE_RESOLUTION * scale, "coarse": COARSE / scale}
    t0 = time.perf_counter()
    res = Result(scene=scene, numerics=numerics)
    if scene.k != 1.0:
        res.reason = f"the quasi-static elastic solver needs k = 1 (got k = {scene.k})"
        return res
    lo, hi = ELASTIC_MU_RANGE
    if not lo <= scene.mu <= hi:
        res.reason = (f"mu = {scene.mu:g} is beyond the elastic branch's range [{lo:g}, "
                      f"{hi:g}]: the crack-front model (model crack or auto), the mu -> "
                      f"infinity limit, answers it")
        return res
    if scene.stop != "pulloff":
        res.reason = ("the quasi-static elastic branch ends at its displacement-controlled "
                      "fold past the pull-off: a run to separation (stop separation) runs "
                      "with model bem or auto")
        return res
    protocol = scene.protocol()
    if protocol is not None:
        try:
            a_start, approach = _protocol_start(scene, protocol, mesh)
        except RuntimeError as err:
            res.reason = f"protocol: {err}"
            res.wall_s = time.perf_counter() - t0
            return res
    elif scene.a0 is None:
        res.reason = "the quasi-static elastic solver starts from a0 (give a0, not delta0)"
        return res
    else:
        a_start, approach = scene.a0, None
    po = elastic_pull_off(scene.mu, a_start=a_start, **mesh)
    res.nodes_used, res.steps = po.nodes, po.solves
    res.newton_iterations = res.factorizations = po.newton_iterations
    if approach is not None:
        res.steps += approach["solves"]
        res.newton_iterations += approach["iterations"]
        res.factorizations = res.newton_iterations
    if not po.converged:
        # below the fold the start exists but cannot be held: a physical refusal, as the
        # BEM's (sweep.engine.tip_following.branch_state), not a numerical failure
        state = state_at(ElasticBranch(scene.mu, a_start, 0.5 * a_start), a_start)
        res.reason = (fold_refusal(scene.mu, a_start) if state is not None and state[2]
                      else po.reason)
        ratio = a_start / pull_off_radius_guess(scene.mu)
        if res.reason == po.reason and ratio > LARGE_START:
            # the pattern scales with the radius: its tip zone at a_start is coarser by the
            # ratio (Newton failed at a0 >= 20 at mu >= 50, about 20 pull-off radii)
            res.reason += (f" (the branch's mesh scales with the contact radius: from a0 = "
                           f"{a_start:g}, {ratio:.0f} times the pull-off radius, its tip zone "
                           f"is under-resolved; the elastic pull-off does not depend on a0 "
                           f"beyond the pull-off radius: a smaller a0 gives it; model auto "
                           f"answers with the crack-front model, within its measured error)")
        res.wall_s = time.perf_counter() - t0
        return res
    res.wall_s = time.perf_counter() - t0
    scales = derive(scene, res.numerics)
    radii, loads, deltas = po.branch
    stop = int(np.argmin(deltas)) + 1          # the displacement-controlled fold
    if scene.machine_stiffness is not None and approach is None:
        # a start whose load falls faster than the spring's stiffness per unit indentation
        # (below the pull-off radius) cannot be held: the sphere jumps off at once
        slope = float((loads[1] - loads[0]) / (deltas[1] - deltas[0]))
        if slope < -scene.machine_stiffness:
            res.reason = (f"the compliant machine cannot hold the start: there dP/ddelta = "
                          f"{slope:.4g} < -K = {-scene.machine_stiffness:.4g} (the contact "
                          f"starts below its pull-off radius, and the sphere jumps off at "
                          f"once); a stiffer machine or a larger a0 holds it")
            res.wall_s = time.perf_counter() - t0
            return res
    keep = radii[:stop] >= po.a
    d0 = float(deltas[0])
    speed = scales.loading_speed
    t_start = 0.0 if approach is None else float(approach["t"][-1])
    res.status = "ok"
    res.reason = po.reason
    res.pull_off, res.a_pulloff, res.delta_pulloff = po.pull_off, po.a, po.delta
    # the machine's displacement, D = delta + P/K (a compliant machine's; delta for a rigid
    # one), falls at rate h0 and sets the clock
    compliance = 0.0 if scene.machine_stiffness is None else 1.0 / scene.machine_stiffness
    D0 = d0 + compliance * float(loads[0])
    res.t_pulloff = t_start + (D0 - (po.delta - compliance * po.pull_off)) / speed
    res.crack_speed = speed / po.ddelta_da
    res.vhat = res.crack_speed / scales.process_zone
    res.rhat_pb = scales.loading_speed
    res.a0_result, res.delta0_result = float(radii[0]), d0
    res.spacing, res.domain_used = po.spacing, po.domain
    res.prony_terms, res.prony_error = 0, 0.0
    if approach is None:
        a_tr = np.append(radii[:stop][keep], po.a)
        d_tr = np.append(deltas[:stop][keep], po.delta)
        P_tr = np.append(loads[:stop][keep], -po.pull_off)
    else:
        try:
            a_tr, d_tr, P_tr = _retraction_records(approach, po)
        except RuntimeError as err:
            res.status, res.reason = "failed", f"protocol: {err}"
            res.wall_s = time.perf_counter() - t0
            return res
    res.trajectory = {"t": t_start + (D0 - (d_tr + compliance * P_tr)) / speed, "delta": d_tr,
                      "P": P_tr, "a": a_tr,
                      "a_inner": np.full(a_tr.size, np.nan)}
    if approach is not None:
        _join_protocol(res, approach)
    _estimate_error(res, a_start, mesh)
    res.wall_s = time.perf_counter() - t0
    return res


#: an elastic protocol's approach is recorded at this many radii (geometric, from first
#: contact to the preload's radius; the retraction passes them again, and over them the
#: trapezoid of the cycle's work cancels) ...
APPROACH_RECORDS = 24
#: ... and the retraction below first contact at this many, to the pull-off: the hysteresis
#: energy's trapezoid (measured at mu 5: 1.23860, 1.23883, 1.23889, 1.23891 with 32, 64, 128,
#: 256 such radii, second order: 6e-5 off at 64)
TAIL_RECORDS = 64


def _protocol_start(scene, protocol, mesh: dict):
    """(the preload's radius, the approach's records) of an elastic scene with a test protocol,
    on the branch's mesh of :func:`elastic_pull_off` (so that the retraction starts from the same
    state). The approach starts where the BEM's does (:func:`sweep.engine.protocol.first_contact`:
    the JKR indentation at zero load, k = 1) and follows the branch, the radius growing, up to
    the radius whose load is the preload; its time is the indentation's travel at
    ``approach_rate h0``. The dwell adds one record ``dwell`` later in the same state (no
    memory: held at force or at depth, nothing moves). Raises RuntimeError where a solve
    fails or the branch is not stable (the indentation not growing with the radius)."""
    mu = scene.mu
    a_g = pull_off_radius_guess(mu)
    br = _branch(mu, **mesh)
    a_first = _first_contact(br, mu)
    a_pre = float(jkr_contact_radius(load=protocol.preload))
    a_end = _branch_root(br, lambda a, h, d: br.load(a, h), protocol.preload, a_pre, a_g)
    if not a_end > a_first:
        raise RuntimeError(f"the preload {protocol.preload:g} is reached at a = {a_end:.4g}, "
                           f"below first contact (a = {a_first:.4g})")
    radii = np.geomspace(a_first, a_end, APPROACH_RECORDS)
    states, loads, failed_at = walk(br, radii)
    if failed_at is not None:
        raise RuntimeError(f"no elastic equilibrium on the approach at a = {failed_at:.4g}")
    deltas = np.array([d for _, d in states])
    if np.any(np.diff(deltas) <= 0.0):
        raise RuntimeError("the elastic branch folds on the approach (the indentation does "
                           "not grow with the radius)")
    h0 = units.h0_hat(mu)
    t = (deltas - deltas[0]) / (protocol.approach_rate * h0)
    approach = {"t": t, "delta": deltas, "P": np.array(loads), "a": radii,
                "phase": np.zeros(radii.size), "solves": br.solves,
                "iterations": br.iterations, "branch": br}
    if protocol.dwell > 0.0:
        for key in ("t", "delta", "P", "a", "phase"):
            approach[key] = np.append(approach[key], approach[key][-1])
        approach["t"][-1] += protocol.dwell
        approach["phase"][-1] = 1.0
    return float(a_end), approach


def _branch(mu, **mesh) -> ElasticBranch:
    """The branch an elastic protocol runs on: sized for the pull-off radius, down to half the
    JKR radius at zero load (first contact; a preload is > 0, its radius larger)."""
    a_g = pull_off_radius_guess(mu)
    a_low = 0.5 * float(jkr_contact_radius(load=0.0))
    return ElasticBranch(mu, a_g, min(0.35 * a_g, a_low), **mesh)


def _first_contact(br, mu) -> float:
    """The radius on ``br`` of the BEM's first contact (:func:`sweep.engine.protocol.
    first_contact`, k = 1): the JKR contact's indentation at zero load."""
    a_zero = float(jkr_contact_radius(load=0.0))
    return _branch_root(br, lambda a, h, d: d, float(jkr_indentation(a_zero)), a_zero,
                        pull_off_radius_guess(mu))


def _cycle_work(br, mu, po) -> float:
    """An elastic protocol's hysteresis energy on the branch ``br`` with its pull-off ``po``:
    the work along the branch from first contact to the pull-off (the trapezoid on
    TAIL_RECORDS radii, as :func:`_retraction_records`'s; where the approach and the
    retraction coincide, theirs cancel), NaN where a solve fails."""
    try:
        _, deltas, loads = _tail(br, _first_contact(br, mu), po)
    except RuntimeError:
        return math.nan
    return cycle_work({"P": loads, "delta": deltas})


def _tail(br, a_from, po):
    """(radii, indentations, loads) along the branch ``br`` from ``a_from`` down to the
    pull-off ``po``: TAIL_RECORDS radii, the last the pull-off's state; just the pull-off
    where ``a_from`` is not above it. Raises RuntimeError where a solve fails."""
    if not a_from > po.a * (1.0 + 1e-9):
        return np.array([po.a]), np.array([po.delta]), np.array([-po.pull_off])
    radii = np.geomspace(a_from, po.a, TAIL_RECORDS)[:-1]
    states, loads, failed_at = walk(br, radii)
    if failed_at is not None:
        raise RuntimeError(f"no elastic equilibrium on the retraction at a = {failed_at:.4g}")
    return (np.append(radii, po.a), np.append([d for _, d in states], po.delta),
            np.append(loads, -po.pull_off))


def _retraction_records(approach, po):
    """(radii, indentations, loads) of an elastic protocol's retraction from the preload's
    radius to the pull-off ``po``: the approach's states passed again in reverse (no memory),
    then the branch below first contact at TAIL_RECORDS radii, then the pull-off. Where
    the two paths share their states the trapezoid of the cycle's work cancels exactly, so
    the hysteresis energy is the branch's integral between first contact and the pull-off."""
    br = approach["branch"]
    n = int(np.sum(approach["phase"] == 0.0))
    a_app, d_app, P_app = (approach[key][:n][::-1] for key in ("a", "delta", "P"))
    passed = a_app > po.a
    a_tail, d_tail, P_tail = _tail(br, a_app[passed][-1], po)
    skip = 1 if a_tail.size > 1 else 0      # the tail's first state is the approach's last
    return (np.append(a_app[passed], a_tail[skip:]), np.append(d_app[passed], d_tail[skip:]),
            np.append(P_app[passed], P_tail[skip:]))


def _branch_root(br, value, target, a_guess, a_low):
    """The radius where ``value(a, h, delta)`` (increasing in a above the branch's pull-off)
    equals ``target`` on the branch ``br``: bracketed from ``a_guess``
    (down to ``a_low``, the expected pull-off radius, and up by half again each try), then
    Brent's method, each solve started from the nearest state solved. Raises RuntimeError
    where a solve fails or no bracket is found."""
    from scipy.optimize import brentq  # lazy: not on a relaxed scene's path

    solved = {}

    def f(a):
        near = min(solved, key=lambda b: abs(b - a)) if solved else None
        h, d = br.guess(a) if near is None else solved[near]
        h, d, ok = br.solve(a, h, d)
        if not ok:
            raise RuntimeError(f"no elastic equilibrium at a = {a:.4g}")
        solved[a] = (h, d)
        return value(a, h, d) - target

    lo, hi = min(a_guess, a_low), max(a_guess, a_low)
    f_lo, f_hi = f(lo), f(hi)
    for _ in range(40):
        if f_hi > 0.0:
            break
        lo, f_lo, hi = hi, f_hi, 1.5 * hi
        f_hi = f(hi)
    if not (f_lo <= 0.0 < f_hi):
        raise RuntimeError(f"no radius on the elastic branch between a = {lo:.4g} and "
                           f"{hi:.4g} reaches {target:.6g}")
    return brentq(f, lo, hi, xtol=1e-14, rtol=4 * np.finfo(float).eps,
                  maxiter=200) if f_lo < 0.0 else lo


def _join_protocol(res, approach) -> None:
    """``res``'s trajectory: the approach's (and the dwell's) records, then the retraction's
    from its second (its first is the approach's last state), with ``phase``
    (:data:`sweep.engine.protocol.PHASES`), and the hysteresis energy of the whole path (to
    the pull-off: the branch's records end there)."""
    tr = res.trajectory
    n = tr["t"].size - 1
    joined = {key: np.concatenate([approach[key], tr[key][1:]])
              for key in ("t", "delta", "P", "a")}
    joined["a_inner"] = np.full(joined["t"].size, np.nan)
    joined["phase"] = np.concatenate([approach["phase"], np.full(n, 2.0)])
    res.trajectory = joined
    res.hysteresis_energy = cycle_work(joined)


def _estimate_error(res, a_start: float, mesh: dict) -> None:
    """The error estimate of an ok elastic result, in place: the pull-off change on the
    branch's mesh at 1/f of the resolution (f times the tip-zone and the coarse spacing)
    over f - 1, as the BEM's (:func:`sweep.engine.resolution.estimate_error`), with
    f = sqrt 2 (at f = 2 the uniform tip zone's error cancellation is lost and the estimate
    grows 60x loose at mu = 30-100); "unresolved" above ``pull_off_rtol``; nothing when it
    is 0. Against a run at twice the resolution it is 3-12x the error from mu = 0.01 to 100."""
    tol = res.numerics.pull_off_rtol
    if tol <= 0:
        return
    check = elastic_pull_off(res.scene.mu, a_start=a_start,
                             zone_resolution=mesh["zone_resolution"] / ELASTIC_CHECK_FACTOR,
                             coarse=mesh["coarse"] * ELASTIC_CHECK_FACTOR)
    if not check.converged:
        res.reason = (f"{res.reason}; " if res.reason else "") + (
            f"no error estimate: the branch at half the resolution failed ({check.reason})")
        return
    change = abs(res.pull_off - check.pull_off) / res.pull_off
    res.error_estimate = change / (ELASTIC_CHECK_FACTOR - 1.0)
    if res.scene.protocol() is not None:
        coarse = _branch(res.scene.mu,
                         zone_resolution=mesh["zone_resolution"] / ELASTIC_CHECK_FACTOR,
                         coarse=mesh["coarse"] * ELASTIC_CHECK_FACTOR)
        res.hysteresis_error = hysteresis_error(res, _cycle_work(coarse, res.scene.mu, check),
                                                ELASTIC_CHECK_FACTOR - 1.0)
    if res.error_estimate > tol:
        res.status = "failed"
        res.reason = (f"unresolved: the pull-off moves by {change:.2g} on the branch at "
                      f"1/{ELASTIC_CHECK_FACTOR:.3g} the resolution, estimate "
                      f"{res.error_estimate:.2g} > pull_off_rtol = {tol:g}")


#: a start this many pull-off radii out, where the branch fails, is named as the cause
LARGE_START = 10.0
#: the Tabor parameters of the branch (:func:`elastic_pull_off`)
ELASTIC_MU_RANGE = (0.01, 100.0)
#: resolution ratio of the elastic branch's error check (:func:`_estimate_error`)
ELASTIC_CHECK_FACTOR = math.sqrt(2.0)
