"""A scene's numbers derived once: the prepared problem the kernels receive.

``prepare(scene, numerics)`` computes, in the units of docs/design.md section 2, everything a
solve needs before it starts -- the Lennard-Jones constants (h0, c), the process zone l0,
the estimated initial state, the domain, the mesh with its influence matrix and load
weights, the Prony time window and series -- so that data flows one way: scene ->
problem -> kernels -> result. The per-process caches (Prony series, influence matrices)
live here and in :mod:`sweep.engine.mesh`.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path

import numpy as np

from .. import materials, units
from ..kernels.interface import TIP_GAP
from ..materials import SLS, MPLRetardation, Prony
from ..materials._checks import MAX_WINDOW_DECADES
from ..materials.prony_series import PronySeries
from ..scene import Numerics, Scene, SceneTable
from ..theory import jkr_contact_radius
from . import diskcache, process_zone
from .mesh import BAND_MARGIN_ZONES, Mesh, crack_band, scene_mesh
from .postprocess import stop_mode

#: the Prony window spans [min_step/rate, WINDOW_SAFETY * estimated unloading time] ...
WINDOW_SAFETY = 10.0
#: ... widened outward to multiples of this many decades (shared by the scenes of a sweep)
WINDOW_GRID = 0.5
#: ... and never beyond this time (tau0): both materials have relaxed by then (MPL: the
#: retardation times are Gamma(n)-distributed, Chat - 1 ~ exp(-2 sqrt(t)) < 1e-80 for
#: n <= 5; SLS: exp(-t)), while a fit over more decades costs seconds (13 s for
#: n = 0.2, k = 1e-4 up to 3e7 at rate 1e-4)
WINDOW_T_MAX = 1e4
#: the crack tip stays this many process zones inside the fine band of a graded mesh
TIP_MARGIN_ZONES = 2.0


#: Tabor parameters of the hereditary BEM: the whole range of Scene. Validated: above about 8
#: the fixed crack band exceeds max_nodes and the tip-following mesh
#: (:mod:`sweep.engine.tip_following`) takes over (pull-off converged to 1 % at mu = 30 and 100);
#: below 1.83 the mesh is sized from sqrt(h0) (:func:`tip_zone`) and the domain from the LJ
#: tail (elastic pull-off equal to the quasi-static branch's to 1e-3 down to mu = 0.01)
BEM_MU_RANGE = (0.01, 100.0)


class Refused(Exception):
    """The numerics cannot represent the scene (the message says what to change)."""


def tip_zone(mu: float) -> float:
    """Length (a_ref) over which the interface traction varies at the crack tip: the unit
    of the fine spacing (tip_zone/band_resolution) and of the band margins of a graded mesh.
    Not to be confused with the process zone l0 (:func:`sweep.units.l0_hat`), the unit of
    ``vhat``: the two are equal for mu >= 1.83.

    The process zone l0 = 1.693/mu^2 on the JKR side. On the DMT side l0 outgrows the
    contact itself (l0 = 17000 at mu = 0.01) and the sphere hardly deforms: the gap near
    the contact edge, whose radius is about sqrt(2 (3^(1/6) - 1) h0) at pull-off, grows
    like the rigid profile r^2/2, by h0 over about sqrt(h0) (h0 = 1/(pi^(2/3) mu)). The
    zone is the smaller of the two: sqrt(h0) below mu = 1.83, where they cross.
    """
    return min(units.l0_hat(mu), math.sqrt(units.h0_hat(mu)))


def lj_constants(mu: float) -> tuple[float, float]:
    """(h0, c) of the LJ law sigma = -c[(h0/h)^3 - (h0/h)^9] for Tabor parameter mu."""
    return units.h0_hat(mu), units.lj_prefactor(mu)


def jkr_radius(delta: float) -> float:
    """JKR contact radius at indentation ``delta`` (stable branch); 0 below the fixed-grip
    fold delta = -3/4, where JKR has no contact."""
    return float(jkr_contact_radius(indentation=delta)) if delta >= -0.75 else 0.0


def material(kind, n: float, k: float):
    """The material object (units E0 = 1, tau0 = 1): "mpl", "sls", or a scene's Prony table
    (:class:`sweep.scene.SceneTable`: its Kelvin form in tau0, k its own)."""
    if kind == "sls":
        return SLS(1.0, 1.0 / k, 1.0)
    if isinstance(kind, SceneTable):
        return Prony(kind.weights, kind.times, E0=1.0, kind="kelvin")
    return MPLRetardation(1.0, 1.0 / k, n, 1.0)


def material_of(scene: Scene):
    """The material object of a scene, in units where E0 = 1 and tau0 = 1."""
    return material(scene.material, scene.n, scene.k)


def auto_domain(h0: float, tail_gap: float, delta0_estimate: float, a0_estimate: float) -> float:
    """Mesh radius (a_ref): the rigid gap r^2/2 - delta0 reaches ``tail_gap`` h0 at the edge,
    and at least 1.3 a0 + 0.5 (``a0_estimate``: the given a0, or JKR at ``delta0_estimate``;
    the JKR radius is 0 where JKR has no contact)."""
    r_tail = math.sqrt(2.0 * (max(delta0_estimate, 0.0) + tail_gap * h0))
    return max(r_tail, 1.3 * a0_estimate + 0.5)


def time_window(rate: float, scales: Scales, min_step: float) -> tuple[float, float]:
    """Prony window [t_min, t_max] in tau0 for a scene's unloading at ``rate`` (r-hat) from
    ``scales.delta0_estimate``, with indentation steps down to ``min_step`` h0.

    The window is widened outward to the grid of WINDOW_GRID decades, so that the scenes
    of a sweep share a few windows (and their cached Prony series, :func:`prony_series`).
    """
    delta0 = scales.delta0_estimate
    t_min = min_step / rate        # the smallest step the run may take
    travel = max(delta0, 0.0) + 3.0 + 2.0 * math.sqrt(max(delta0, 1.0))
    # the travel at this rate (a protocol's approach has its own; the scene's loading speed,
    # its retraction's, had bounded a slow approach's window by the fast retraction's: n 1.48,
    # k 0.009283, mu 6.87, approach rate 30.2, rate 62490 marched to t = 0.47 tau0 on a series
    # fitted to 0.032, its compliance 25-54 % off beyond, the pull-off 6.3 % off)
    t_max = max(min(WINDOW_SAFETY * travel / (rate * scales.h0), WINDOW_T_MAX), 10 * t_min)
    lo = math.floor(math.log10(t_min) / WINDOW_GRID) * WINDOW_GRID
    hi = math.ceil(math.log10(t_max) / WINDOW_GRID) * WINDOW_GRID
    return 10.0 ** lo, 10.0 ** hi


@lru_cache(maxsize=256)
def prony_series(kind: str, n: float, k: float, t_min: float, t_max: float, rtol: float):
    """The Prony series of a material's creep compliance on [t_min, t_max] (tau0), cached.

    A fit costs 0.02-0.2 s (about 60 ms on the threshold campaign), more than a fast
    scene's unloading; the scenes of a sweep repeat the same (material, n, k) and, through
    the snapped :func:`time_window`, the same window (156 windows for the 936 scenes of
    configs/threshold.yaml). Each fit is kept in memory and on disk
    (:mod:`sweep.engine.diskcache`, keyed by its arguments and a hash of sweep/materials), so a
    worker or a later sweep reads it instead of fitting it again.
    """
    key = (kind, float(n), float(k), float(t_min), float(t_max), float(rtol))
    path = diskcache.record_path("prony", _materials_tag, key)
    if path is not None:
        got = diskcache.load(path)
        if got is not None and _PRONY_FIELDS <= set(got) and tuple(got["key"]) == key[1:] \
                and str(got["kind"]) == kind:
            return PronySeries(weights=got["weights"], times=got["times"],
                               max_rel_error=float(got["max_rel_error"]),
                               rtol=float(got["rtol"]), converged=bool(got["converged"]),
                               k=float(got["k"]), t_min=float(got["t_min"]),
                               t_max=float(got["t_max"]))
    series = material(kind, n, k).prony(t_min, t_max, rtol)
    if path is not None:
        diskcache.save(path, {"kind": np.array(kind), "key": np.array(key[1:]),
                              "weights": series.weights, "times": series.times,
                              **{f: np.array(getattr(series, f)) for f in (
                                  "max_rel_error", "rtol", "converged", "k", "t_min",
                                  "t_max")}})
    return series


_PRONY_FIELDS = {"kind", "key", "weights", "times", "max_rel_error", "rtol", "converged", "k",
                 "t_min", "t_max"}


def _materials_tag() -> str:
    """Hash of the material and fitting code (sweep/materials/*.py): a cached series is
    used only with the code that fitted it."""
    folder = Path(materials.__file__).parent
    return diskcache.source_tag(*sorted(str(p) for p in folder.glob("*.py")))


@dataclass(frozen=True)
class Problem:
    """Everything a BEM solve of one scene needs, derived once (docs/design.md section 2 units).

    Attributes
    ----------
    scene, numerics : the inputs.
    scales : the scene's :class:`Scales` (h0, the tip gap, the process and tip zones, the
        loading speed, the initial estimates); ``h0``, ``c``, ``hm`` (the tip gap) and
        ``tip_zone`` read from it.
    mesh : the mesh (``mesh.r`` node radii, ``mesh.spacing`` the fine spacing).
    A, wP : influence matrix and load weights of the mesh (read-only, cached).
    prony_weights, prony_times : Prony modes of Chat (empty when elastic or exact): the
        series fitted on the scene's time window, or a table material's own Kelvin terms.
    prony_error : achieved max relative error of the series (0 when none, or a table's).
    prony_t_max : the end of the window the series was fitted on (tau0; infinite for a
        table's own terms or none): past it the series' compliance is not the material's
        (:func:`sweep.engine.bem.check_prony_window`).
    """

    scene: Scene
    numerics: Numerics
    scales: Scales
    mesh: Mesh
    A: np.ndarray
    wP: np.ndarray
    prony_weights: np.ndarray
    prony_times: np.ndarray
    prony_error: float
    prony_t_max: float = math.inf

    @property
    def h0(self) -> float:
        """LJ range (d_ref)."""
        return self.scales.h0

    @property
    def c(self) -> float:
        """LJ prefactor."""
        return self.scales.c

    @property
    def hdot_c(self) -> float:
        """The process zone's opening-rate scale (d_ref / tau0; inf: none, the LJ law),
        :func:`sweep.engine.process_zone.hdot_c`."""
        return process_zone.hdot_c(self.scene)

    @property
    def pz_xi(self) -> float:
        """The process zone's exponent (0 without one)."""
        return 0.0 if self.scene.pz_law == "none" else float(self.scene.pz_xi)

    @property
    def machine_compliance(self) -> float:
        """1/K, the compliance of the machine in series with the sphere (d_ref per pi dg R;
        0: a rigid machine, the default)."""
        K = self.scene.machine_stiffness
        return 0.0 if K is None else 1.0 / float(K)

    @property
    def hm(self) -> float:
        """The gap at the crack tip, 3^(1/6) h0 (d_ref)."""
        return self.scales.tip_gap

    @property
    def tail(self) -> float:
        """The mesh's :attr:`sweep.engine.mesh.Mesh.tail_rise`: the load's Lennard-Jones tail
        beyond the mesh starts at the gap h_last + tail (:func:`sweep.kernels.solve.load`);
        inf (no tail) where ``numerics.lj_tail`` is False."""
        return self.mesh.tail_rise if self.numerics.lj_tail else math.inf

    def mesh_arrays(self):
        """The unloading kernels' :data:`sweep.kernels.solve.MeshArrays` of this problem."""
        from ..kernels.solve import MeshArrays
        return MeshArrays(self.A, self.mesh.r, self.wP, self.tail)

    def load(self, sigma, h) -> float:
        """P = 2 pi wP . sigma + the Lennard-Jones tail beyond the mesh, of the gaps ``h``
        whose tractions are ``sigma`` (:func:`sweep.kernels.solve.load`)."""
        from ..kernels.solve import load
        return float(load(sigma, self.wP, h, self.tail, self.h0, self.c))

    @property
    def tip_zone(self) -> float:
        """The mesh's resolution unit (a_ref), :attr:`Scales.tip_zone`."""
        return self.scales.tip_zone

    @property
    def tip_range(self) -> tuple[float, float]:
        """Radii the crack tip must stay within: the fine band less TIP_MARGIN_ZONES l0 at
        each end that has a coarse region beyond it."""
        lo, hi = self.mesh.band
        lo = lo + TIP_MARGIN_ZONES * self.tip_zone if lo > 0 else -1.0
        hi = hi - TIP_MARGIN_ZONES * self.tip_zone if hi < self.mesh.domain else math.inf
        return lo, hi

    @property
    def stop_mode(self) -> int:
        """The stop rule's mode (:func:`sweep.engine.postprocess.stop_mode`)."""
        return stop_mode(self.scene)


@dataclass(frozen=True)
class Scales:
    """The numbers every model of a scene derives from (scene, numerics): derived once, by
    :func:`derive`, and read from here by the meshes, the solvers, the resolution checks and
    the result (docs/design.md section 2 units).

    Attributes
    ----------
    h0 : LJ range (d_ref), ``1/(pi^(2/3) mu)``.
    c : LJ prefactor, ``sigma = -c [(h0/h)^3 - (h0/h)^9]``.
    tip_gap : the gap at the crack tip, ``3^(1/6) h0`` (d_ref): where the traction is most
        tensile; the contact radius ``a`` is where the gap equals it.
    process_zone : the Persson-Brener process zone ``l0 = 1.693/mu^2`` (a_ref), the unit of
        ``vhat`` (:func:`sweep.units.l0_hat`).
    tip_zone : the length over which the traction varies at the tip (a_ref,
        :func:`tip_zone`), the unit of the meshes' fine spacing; equal to ``process_zone``
        for mu >= 1.83, ``sqrt(h0)`` below.
    loading_speed : ``rate h0`` (d_ref/tau0): d delta/dt = -loading_speed; also the paper's
        ``rhat_PB`` (:func:`sweep.units.rhat_pb`).
    delta0_estimate, a0_estimate : the initial state before it is solved (delta0 given, or
        JKR from a0), d_ref and a_ref; they size the domain, the crack band and the time window.
    domain : mesh radius (a_ref): ``numerics.domain`` or :func:`auto_domain`.
    """

    h0: float
    c: float
    tip_gap: float
    process_zone: float
    tip_zone: float
    loading_speed: float
    delta0_estimate: float
    a0_estimate: float
    domain: float


@lru_cache(maxsize=1024)
def derive(scene: Scene, numerics: Numerics) -> Scales:
    """The :class:`Scales` of a scene under its numerics (cached per process: the model
    dispatch, the mesh and the solver of one scene read the same object)."""
    h0, c = lj_constants(scene.mu)
    protocol = scene.protocol()
    # a protocol's largest contact: the relaxed JKR radius at the preload (a dwell at force
    # creeps toward it; the approach, stiffer, stays inside it)
    a_given = float(jkr_contact_radius(load=protocol.preload)) if protocol else scene.a0
    if scene.delta0 is not None:
        d_est = scene.delta0
    else:
        d_est = a_given**2 - math.sqrt(2 * a_given)
    a_est = a_given if a_given is not None else max(jkr_radius(d_est), 0.0)
    domain = (numerics.domain if numerics.domain is not None
              else auto_domain(h0, numerics.tail_gap, d_est, a_est))
    return Scales(h0=h0, c=c, tip_gap=TIP_GAP * h0, process_zone=units.l0_hat(scene.mu),
                  tip_zone=tip_zone(scene.mu), loading_speed=scene.rate * h0,
                  delta0_estimate=float(d_est), a0_estimate=float(a_est), domain=float(domain))


def initial_estimates(scene: Scene, numerics: Numerics) -> tuple[float, float, float]:
    """(indentation, contact radius, mesh radius) a scene's mesh is sized from: the JKR
    estimates of the initial state (d_ref, a_ref, a_ref) and the automatic (or given) domain
    (the :class:`Scales` of :func:`derive`)."""
    s = derive(scene, numerics)
    return s.delta0_estimate, s.a0_estimate, s.domain


def protocol_band(scene: Scene, numerics: Numerics) -> tuple[float, float]:
    """[lo, hi] (a_ref) of the crack band of a scene with a test protocol: every radius its
    crack tip takes. The approach starts at first contact, the glassy JKR contact at zero
    load, of radius k^(1/3) times the relaxed one (:func:`sweep.engine.protocol.first_contact`;
    the scene's k, the glassy compliance, below the fitted series' 1 - sum w: a radius no
    larger), and its contact grows to the preload's; the retraction's tip sweeps from there
    as any scene's does. The band is the retraction's from the relaxed JKR radius at the
    preload (:func:`sweep.engine.mesh.crack_band`; down to r = 0 where the scene follows the
    curve to separation), reaching in to first contact less BAND_MARGIN_ZONES tip zones
    where that lies inside it; inside the band the mesh is graded as a relaxed start's."""
    s = derive(scene, numerics)
    lo, hi = crack_band(s.a0_estimate, s.tip_zone, pull_off_only=scene.stop == "pulloff")
    first = first_contact_radius(scene)
    return max(min(lo, first - BAND_MARGIN_ZONES * s.tip_zone), 0.0), hi


def first_contact_radius(scene: Scene) -> float:
    """The contact radius (a_ref) at which a test protocol's approach starts: the glassy JKR
    contact at zero load, k^(1/3) times the relaxed one (:func:`sweep.engine.protocol.first_contact`
    solves it on the mesh)."""
    return scene.k ** (1.0 / 3.0) * float(jkr_contact_radius(load=0.0))


def prepare(scene: Scene, numerics: Numerics, band: tuple | None = None, *,
            window: bool = False) -> Problem:
    """Derive a scene's numbers once. Raises :class:`Refused` when the mesh cannot do.

    ``band`` overrides the crack band of a graded mesh (a_ref radii, see
    :func:`sweep.engine.mesh.crack_band`); ``window``: that band is the tip-following mesh's
    window (:mod:`sweep.engine.tip_following`), which a refusal names.
    """
    lo, hi = BEM_MU_RANGE
    if not lo <= scene.mu <= hi:
        others = (", the one model that runs a test protocol or a compliant machine"
                  if scene.protocol() is not None or scene.machine_stiffness is not None else
                  "; beyond it the crack-front model (model crack or auto), the large-mu limit, "
                  "answers it")
        raise Refused(f"mu = {scene.mu:g} is outside the hereditary BEM's range [{lo:g}, {hi:g}]"
                      f"{others}")
    protocol = scene.protocol()
    if protocol and numerics.exact:
        raise Refused("a protocol's approach and dwell run the hereditary BEM's time march: "
                      "not with numerics.exact")
    if protocol and band is None:
        band = protocol_band(scene, numerics)
    if scene.machine_stiffness is not None and numerics.exact:   # a protocol: Scene refuses
        raise Refused("a compliant machine (machine_stiffness) runs on the BEM's unloading "
                      "from a relaxed contact: not with numerics.exact")
    if numerics.exact and scene.pz_law != "none":
        raise Refused(f"numerics.exact: the exact hereditary reference has the Lennard-Jones "
                      f"interface only, not the process zone (pz_law {scene.pz_law}); leave "
                      f"exact unset")
    s = derive(scene, numerics)
    zone_length, domain = s.tip_zone, s.domain
    mesh = scene_mesh(numerics, zone_length, s.a0_estimate, domain,
                      pull_off_only=scene.stop == "pulloff", band=band)
    zone = zone_length / mesh.spacing
    if zone < numerics.zone_nodes:
        if mesh.kind == "uniform":
            need = int(math.ceil(numerics.zone_nodes * domain / zone_length)) + 1
            advice = f"use nodes >= {need} for domain {domain:.3g}"
        else:
            advice = "use more nodes (or leave nodes unset to size the mesh from band_resolution)"
        raise Refused(f"mesh too coarse: the tip zone {zone_length:.3g} a_ref spans {zone:.2g} "
                      f"node spacings (< zone_nodes = {numerics.zone_nodes:g}); {advice}")
    if mesh.nodes > numerics.max_nodes:
        # a compliant machine runs on the graded or uniform mesh only (docs/design.md)
        other = ("" if window else
                 "; a compliant machine runs only on this mesh, never the tip-following one"
                 if scene.machine_stiffness is not None else
                 "; or run it on the tip-following mesh (sweep.engine.tip_following; model "
                 "bem does so)")
        raise Refused(f"mesh too large: the {'window' if window else 'crack band'} needs "
                      f"{mesh.nodes} nodes at band_resolution {numerics.band_resolution:g} (> "
                      f"max_nodes = {numerics.max_nodes}); raise max_nodes or lower "
                      f"band_resolution{other}")
    weights = times = np.zeros(0)
    error, t_fitted = 0.0, math.inf
    if scene.table is not None and not numerics.exact:
        # the table IS the series: its Kelvin form in tau0, every term, no fit (error 0)
        weights = np.ascontiguousarray(scene.table.weights, dtype=float)
        times = np.ascontiguousarray(scene.table.times, dtype=float)
    elif scene.k < 1.0 and not numerics.exact:
        t_min, t_max = time_window(scene.rate, s, numerics.min_step)
        if protocol:        # the approach's steps and the dwell, before the retraction
            t_approach = time_window(protocol.approach_rate, s, numerics.min_step)
            t_min = min(t_min, t_approach[0])
            t_max = max(t_max, 10.0 ** math.ceil(math.log10(t_approach[1] + protocol.dwell +
                                                            t_max)))
            if math.log10(t_max / t_min) > MAX_WINDOW_DECADES:
                raise Refused(f"the test protocol's times span {t_min:.3g} to {t_max:.3g} tau0 "
                              f"(the approach's smallest steps to the retraction at rate "
                              f"{scene.rate:g}), more than a Prony series spans "
                              f"(1e{MAX_WINDOW_DECADES:g}): bring the approach's and the "
                              f"retraction's rates within about 1e{MAX_WINDOW_DECADES - 5:g} "
                              f"of each other")
        n = scene.n if scene.material == "mpl" else 0.0
        prony = prony_series(scene.material, n, scene.k, t_min, t_max, numerics.prony_rtol)
        weights = np.ascontiguousarray(prony.weights, dtype=float)
        times = np.ascontiguousarray(prony.times, dtype=float)
        error, t_fitted = float(prony.max_rel_error), float(prony.t_max)
    return Problem(scene=scene, numerics=numerics, scales=s, mesh=mesh, A=mesh.influence,
                   wP=mesh.load_weights, prony_weights=weights, prony_times=times,
                   prony_error=error, prony_t_max=t_fitted)
