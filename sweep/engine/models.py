r"""Models of one scene and the registry that maps a model name to its simulate function.

=======  ======================================================================================
name     model
=======  ======================================================================================
bem      the boundary-element model (:func:`sweep.engine.bem.simulate`): LJ interface, hereditary
         integral; the reference. On a graded mesh whose fixed crack band would need more
         than ``max_nodes`` nodes (mu above about 8, or large a0) it runs on a mesh refined
         around the crack tip that follows it (:mod:`sweep.engine.tip_following`,
         :func:`wants_tip_following`)
crack    the crack-front model (:func:`sweep.engine.crack_front.simulate_crack`): JKR contact whose
         edge opens with the Persson-Brener Gamma(v) of the scene's spectrum, times the
         process zone's Gamma_pz(v) where the scene has one (``pz_law``): the one model
         that runs a rate-dependent process zone (the others refuse it,
         :data:`PROCESS_ZONE_REFUSALS`)
pb       the paper's closed-form estimate (:func:`pb_estimate`): the crack speed at pull-off
         from the paper's fit vhat = 2.887 rhat_PB^1.171, Gamma_PB at that speed, and the
         load-control JKR pull-off with it, P = 1.5 Gamma_PB
elastic  the quasi-static elastic branch (:func:`sweep.engine.quasistatic.simulate_elastic`), no
         hereditary machinery: k = 1 scenes over the whole Tabor range 0.01-100, from a0 or
         with a test protocol; "bem" and "auto" scenes that are elastic and quasi-static run
         it (:func:`wants_quasistatic`)
auto     the cheapest model whose error meets ``numerics.pull_off_rtol`` (:func:`model_choice`):
         the BEM for a test protocol (the elastic branch at k = 1); the crack-front model
         first for a scene with a process zone (the BEM where its error, the process
         zone's term included, misses the tolerance); the elastic branch for elastic
         quasi-static scenes; the PB estimate or the crack-front model where their
         error against the BEM, measured over a random sample (:func:`measured_error`,
         ``make model-errors``), fits; else the BEM (graded or
         tip-following mesh), and the crack-front model where the BEM fails for a reason the
         crack-front model lifts (the tip zone unresolvable) or beyond the BEM's Tabor range
         (mu > 100, the crack-front model is its limit). ``model_reason`` says why
=======  ======================================================================================

Every simulate function takes ``(scene, numerics=None)`` and returns a :class:`sweep.Result`;
the store and the analysis do not care which ran.
"""
from __future__ import annotations

import dataclasses
import json
import math
import time
from functools import lru_cache
from pathlib import Path
from typing import NamedTuple


from .. import units
from ..errors import (NUMERICAL_ERRORS, check_choice, check_positive, is_internal_error,
                      is_physical_refusal, shortened)
from ..scene import MATERIALS, Numerics, Result, Scene, SceneTable
from ..theory import paper_v_vs_r_fit, pb_gamma_eff, pb_gamma_eff_spectrum
from . import bem, budget
from .crack_front import (FIXED_GRIP_A_MIN, NEGLIGIBLE_PROCESS_ZONE, negligible_zone_term,
                          simulate_crack)
from .mesh import band_nodes, scene_mesh, window_nodes
from .postprocess import FOLD_REASON
from .problem import BEM_MU_RANGE, derive, protocol_band
from .resolution import refined, unresolved, zone_smoothing_error
from .quasistatic import simulate_elastic

__all__ = ["MODELS", "MACHINE_REFUSALS", "PROCESS_ZONE_REFUSALS", "PROTOCOL_REFUSALS",
           "TABLE_REFUSALS",
           "simulate", "pb_estimate", "simulate_pb", "simulate_model",
           "simulate_scene", "choose_model", "model_choice", "Choice", "measured_error",
           "bem_nodes_needed", "bem_node_budget", "wants_quasistatic", "wants_tip_following"]


def pb_estimate(n, k, mu, rate, material="mpl", prefactor=2.887, exponent=1.171) -> dict:
    r"""The paper's closed-form pull-off estimate from Persson-Brener theory.

    .. math::
        \hat v = 2.887\,\hat r_{PB}^{1.171},\quad \hat r_{PB} = \widehat{rate}\,\hat h_0(\mu),
        \qquad \hat P_{po} = 1.5\,\hat\Gamma_{PB}(\hat v)

    (the paper's v-r fit, eq. Vvsr, with ``rhat_PB = r tau0/d_ref`` as in
    :func:`sweep.units.rhat_pb`; the fit constants may be replaced by the project's own).

    Parameters
    ----------
    n, k, mu : float
        Material exponent, ``E0/Einf``, Tabor parameter.
    rate : float or array_like
        The paper's r-hat ``r tau0 / h0`` (> 0).
    material : {"mpl", "sls"} or SceneTable
        A table (:class:`sweep.scene.SceneTable`): its discrete retardation spectrum in
        :func:`sweep.theory.pb_gamma_eff_spectrum` (the estimate needs only Gamma_PB, which
        every spectrum has; the v-r fit is the paper's, measured on the MPL, as for "sls").
    prefactor, exponent : float
        Constants of the v-r fit.

    Returns
    -------
    dict
        ``pull_off`` (pi dg R), ``vhat`` (v tau0/l0), ``crack_speed`` (a_ref/tau0),
        ``gamma`` (Gamma/dg), ``rhat_pb``.
    """
    if isinstance(material, SceneTable):
        weights, times = material.weights, material.times
    else:
        material = check_choice("material", material, MATERIALS)
        weights, times = [1.0], [1.0]
    rhat = units.rhat_pb(rate, mu)
    vhat = paper_v_vs_r_fit(rhat, prefactor, exponent)
    if material == "mpl":
        gamma = pb_gamma_eff(n, k, vhat)
    else:
        gamma = pb_gamma_eff_spectrum(weights, times, k, vhat)
    return {"pull_off": 1.5 * gamma, "vhat": vhat,
            "crack_speed": units.crack_speed_from_vhat(vhat, mu), "gamma": gamma,
            "rhat_pb": rhat}


def simulate_pb(scene, numerics=None):
    """:func:`pb_estimate` of a :class:`sweep.Scene` as a :class:`sweep.Result` row.

    Only ``pull_off``, ``crack_speed``, ``vhat``, ``rhat_pb`` are set (no trajectory, no
    state at pull-off; the initial state does not enter the estimate).
    """
    numerics = Numerics.preset("balanced") if numerics is None else numerics
    t0 = time.perf_counter()
    res = Result(scene=scene, numerics=numerics)
    check_positive("rate", scene.rate)
    est = pb_estimate(scene.n, scene.k, scene.mu, scene.rate, scene.material)
    res.status = "ok"
    res.pull_off = float(est["pull_off"])
    res.crack_speed, res.vhat = float(est["crack_speed"]), float(est["vhat"])
    res.rhat_pb = float(est["rhat_pb"])
    res.prony_terms, res.prony_error = 0, 0.0
    res.wall_s = time.perf_counter() - t0
    return res


def _bem(scene, numerics=None):
    """The BEM, refined where its error estimate exceeds ``pull_off_rtol`` and
    ``numerics.refinements`` allows (:func:`sweep.engine.resolution.refined`), each solve on
    the mesh that fits it (graded, or tip-following beyond ``max_nodes``), within the scene's
    time budget. The row keeps the requested numerics (its id) and records the resolution
    behind it (``refinements``, ``band_resolution_used``, ``step_used``); a refinement that
    fails for another reason (the mesh too large, the budget spent, a fold) leaves the finest
    unresolved row, its reason saying so. A row whose first solve folds is solved once more,
    finer (:func:`_folded`)."""
    numerics = Numerics.preset("balanced") if numerics is None else numerics
    t_start = time.perf_counter()
    res, used, count = _bem_once(scene, numerics), numerics, 0
    while _refinable(res, scene) and count < numerics.refinements and budget.remaining() > 0:
        finer = refined(used, res)
        if finer is None:
            break
        attempt = _bem_once(scene, finer)
        if _folded(attempt) and _folded(res):       # a fold is refined once (_folded)
            res, used, count = attempt, finer, count + 1
            res.reason += "; not refined further: the finer mesh folds too"
            break
        if not (attempt.ok or (_refinable(attempt, scene) and not _folded(attempt))):
            res.reason += (f"; refined to band_resolution {finer.band_resolution:.4g}, step "
                           f"{finer.step:.3g}: {shortened(attempt.reason, 160)}")
            break
        res, used, count = attempt, finer, count + 1
    if _refinable(res, scene) and count < numerics.refinements and budget.remaining() <= 0:
        res.reason += "; not refined further: the time budget is spent"
    if count:
        note = (f"refined {count} time{'s' if count > 1 else ''} to band_resolution "
                f"{used.band_resolution:.4g}, step {used.step:.3g} h0")
        res.reason = f"{res.reason}; {note}" if res.reason else note
    res.numerics, res.refinements = numerics, count
    graded = used.mesh == "graded" and used.nodes is None
    res.band_resolution_used = used.band_resolution if graded else math.nan
    res.step_used = used.step
    res.wall_s = time.perf_counter() - t_start
    return res


def _refinable(res, scene) -> bool:
    """Whether a finer resolution may answer the failed BEM row ``res`` of ``scene``: its
    estimate exceeds ``pull_off_rtol`` (unresolved; not where the process zone's smoothed
    law alone does, :func:`sweep.engine.resolution.zone_smoothing_error`, which no mesh
    changes), or its relaxed start failed on the mesh
    ("initial state: ...", e.g. a contact of a few spacings whose indentation the coarse mesh
    cannot bracket: measured at the fast resolution on n 0.3724, k 0.001749, mu 9.684, a0
    0.6012, rate 0.0012, which the balanced one solves), or its unloading found no
    equilibrium where the discrete path folds (:func:`_folded`) and no other model can
    answer the scene (a test protocol: :func:`_fallback`; a relaxed start's fold is the
    crack-front model's under "auto", which a refinement would leave no time for: n 0.1787,
    mu 98.55, rate 1.5e8 spent its 20 s budget refining and failed, where the crack-front
    model answers it in 0.1 s). :func:`sweep.engine.resolution.refined` then takes the
    largest factor, the failure having no estimate."""
    return ((unresolved(res) and not zone_smoothing_error(res) > res.numerics.pull_off_rtol)
            or (res.status == "failed" and res.reason.startswith("initial state:"))
            or (_folded(res) and _fallback(scene, res, "bem") is None))


def _folded(res) -> bool:
    """Whether ``res`` failed where its discrete path folds before the pull-off, the crack tip
    under-resolved: a finer band may carry the path through (:func:`_bem` tries one finer
    solve, not more: of the four such protocols of the random samples one was answered, at
    mu 18; on the other three the fold moved and stayed, also at up to three refinements,
    each costing four to eight times the last; docs/numerics.md, "Asking for an
    accuracy")."""
    return res.status == "failed" and res.reason.startswith(FOLD_REASON)


def _bem_once(scene, numerics):
    """One BEM solve with its error estimate, on the mesh that fits ``numerics``
    (:func:`wants_tip_following`)."""
    if wants_tip_following(scene, numerics):
        from .tip_following import simulate_tip_following  # lazy: scipy.interpolate, optimize

        return simulate_tip_following(scene, numerics)
    return bem.simulate(scene, numerics)


#: a graded mesh sized from the band resolution runs as the tip-following mesh where its
#: fixed crack band has this many times the nodes of the tip-following mesh (or more): a
#: time step costs about nodes^2 (the dense residual), and the band grows with a0 while the
#: window does not; where the tip leaves the band (slow rates) the graded mesh also solves
#: the scene twice. Measured on the threshold grid at mu 3.24 with the balanced preset
#: (n 0.4-1.6, k 0.1, rates 1-1e6, 2026-11-25): at a0 = 4.5 (1.16 times) the 32 scenes took
#: 14.5 s of scene wall on the window against 25.7 s on the band, at a0 = 4 (1.08 times)
#: 13.1 s against 12.1 s; pull-offs within 5e-5 of each other (docs/performance.md)
TIP_FOLLOWING_NODE_RATIO = 1.1


def wants_tip_following(scene, numerics) -> bool:
    """Whether a BEM scene runs on the tip-following mesh (:mod:`sweep.engine.tip_following`):
    a graded mesh sized from the band resolution (``nodes`` unset, not ``exact``) whose
    fixed crack band would need more than ``numerics.max_nodes`` nodes (large mu or a0), or
    :data:`TIP_FOLLOWING_NODE_RATIO` times the nodes of the window that follows the tip (the
    cheaper mesh at equal resolution). Never a scene with a compliant machine; a scene with
    a test protocol only where the graded mesh, whose band reaches in to first contact, would
    need more than ``max_nodes`` (its march follows the growing contact on the window,
    :class:`sweep.engine.tip_following.MarchWindow`; elsewhere the graded mesh runs it, as it
    did before the window could). A process zone is carried across the re-meshings
    (:func:`sweep.engine.tip_following.transfer`)."""
    if not (numerics.mesh == "graded" and numerics.nodes is None and not numerics.exact):
        return False
    if scene.machine_stiffness is not None:
        return False
    if not BEM_MU_RANGE[0] <= scene.mu <= BEM_MU_RANGE[1]:
        return False      # the BEM refuses it at once (problem.prepare); its graded mesh at
        #                   mu 1e4 has 8e8 nodes, 12.6 GB built to be counted
    graded = bem_nodes_needed(scene, numerics)
    if graded > numerics.max_nodes:
        return True
    if scene.protocol() is not None:
        return False
    s = derive(scene, numerics)
    return graded >= TIP_FOLLOWING_NODE_RATIO * window_nodes(numerics, s.tip_zone,
                                                             s.a0_estimate, s.domain)


def bem_nodes_needed(scene, numerics=None) -> int:
    """Nodes the BEM needs for ``scene``.

    Uniform mesh: its automatic (or given) domain over the spacing at which the process zone
    ``l0 = 1.693/mu^2`` spans ``numerics.zone_nodes`` spacings. Graded mesh: the nodes of
    the mesh the solver would build (:func:`sweep.engine.mesh.band_nodes`, sized from the band
    resolution; with a test protocol, its band reaching in to first contact,
    :func:`sweep.engine.problem.protocol_band`).
    """
    numerics = Numerics.preset("balanced") if numerics is None else numerics
    s = derive(scene, numerics)
    if numerics.mesh == "uniform":
        return int(math.ceil(s.domain * numerics.zone_nodes / s.tip_zone)) + 1
    if scene.protocol() is not None:
        return scene_mesh(dataclasses.replace(numerics, nodes=None), s.tip_zone, s.a0_estimate,
                          s.domain, pull_off_only=scene.stop == "pulloff",
                          band=protocol_band(scene, numerics)).nodes
    return band_nodes(numerics, s.tip_zone, s.a0_estimate, s.domain,
                      pull_off_only=scene.stop == "pulloff")


def bem_node_budget(numerics) -> int:
    """The most nodes ``numerics`` lets the BEM use: ``nodes`` (uniform) or ``max_nodes``."""
    return numerics.uniform_nodes if numerics.mesh == "uniform" else numerics.max_nodes


#: the measurement of the cheaper models against the BEM (``make model-errors``,
#: :mod:`sweep.bench.model_errors`): a random sample over mu, n, k, rate, a0 and the envelope
#: of the differences fitted over mu and the amplification
MODEL_ERRORS = Path(__file__).with_name("model_errors.json")
#: the margin on the envelope (which passes through the largest measured difference): a
#: scene between the measured ones may differ more than the sample's largest
MEASURED_ERROR_MARGIN = 1.5
#: models in order of cost, the cheapest first ("auto" takes the first whose error fits)
BY_COST = ("pb", "crack", "bem")


@lru_cache(maxsize=1)
def _fits() -> dict:
    doc = json.loads(MODEL_ERRORS.read_text())
    return {name: doc[name]["fit"] for name in ("crack", "pb")}


def amplification(pull_off: float) -> float:
    """``max(P / 1.5, 1)``: a pull-off over the elastic JKR one, the second variable of the
    measured error (:func:`measured_error`): the models' difference from the BEM grows with
    it (a strongly amplified crack opens with a tip zone much smaller than l0)."""
    return max(pull_off / 1.5, 1.0)


def measured_error(model: str, mu: float, amplification: float = 1.0) -> float:
    """The relative pull-off error of the crack-front model ("crack") or the PB estimate
    ("pb") against the BEM, from their measured differences (:data:`MODEL_ERRORS`): the
    envelope ``exp(b0 + shift) mu^b_mu A^b_amp`` through the largest of them, times
    :data:`MEASURED_ERROR_MARGIN`, at Tabor parameter ``mu`` and amplification ``A``
    (:func:`amplification` of the model's pull-off; 1, the smallest, before it ran). Beyond
    the largest measured mu it is held at that mu's value: the crack-front model is the
    mu -> infinity limit, but its difference from the BEM does not fall with mu everywhere
    (a physics review measured -0.9, +2.6 and +5.1 % at mu 10, 15 and 30 on n 0.8, k 0.1,
    a0 3, rate 10^2.5, and +3.7 % at both mu 30 and 100 on n 0.8, k 0.5, a0 1.2, rate 1: the
    held envelope covered each, the last by 1.3 times). NaN below the smallest measured mu
    (not measured; the row's reason says so) and for other models."""
    if model not in ("crack", "pb"):
        return math.nan
    f = _fits()[model]
    lo, hi = f["mu_range"]
    if mu < lo:
        return math.nan
    log_err = (f["b0"] + f["shift"] + f["b_mu"] * math.log(min(mu, hi))
               + f["b_amp"] * math.log(max(amplification, 1.0)))
    return MEASURED_ERROR_MARGIN * math.exp(log_err)


class Choice(NamedTuple):
    """A model for a scene, why, and its expected relative pull-off error (NaN: the model
    states its own, e.g. the BEM's error estimate)."""
    model: str
    reason: str
    error: float = math.nan


#: the ranges each model accepts, beyond the Scene's declared limits (their union): the
#: BEM and the elastic branch the Tabor range of the LJ interface they resolve, the elastic
#: branch k = 1 only; the crack-front model, the mu -> infinity limit, any mu but contacts
#: that are stable under fixed grip; the PB estimate every scene
MODEL_RANGES = {"bem": {"mu": BEM_MU_RANGE},
                "elastic": {"mu": BEM_MU_RANGE, "k": (1.0, 1.0)},
                "crack": {"a0": (FIXED_GRIP_A_MIN, math.inf)},
                "pb": {}}


def _accepts(model: str, scene) -> bool:
    """Whether ``model`` can answer ``scene`` at all (:data:`MODEL_RANGES`)."""
    return all(getattr(scene, axis) is None or lo <= getattr(scene, axis) <= hi
               for axis, (lo, hi) in MODEL_RANGES[model].items())


def model_choice(scene, numerics=None) -> Choice:
    """The model "auto" runs first for ``scene``: the BEM for a test protocol (the one model
    that runs one, but for an elastic quasi-static scene's: the elastic branch); the
    crack-front model for a scene with a process zone (``pz_law``; the
    elastic branch and pb refuse it); the quasi-static elastic branch
    for an elastic quasi-static scene; beyond the BEM's Tabor range the crack-front model, its
    mu -> infinity limit; else the cheapest model (:data:`BY_COST`) whose
    :func:`measured_error` at the smallest amplification meets ``numerics.pull_off_rtol``,
    else the BEM (graded or tip-following mesh). :func:`simulate_model` checks a cheaper
    model's error again at the amplification it computed and runs the BEM where it misses."""
    numerics = Numerics.preset("balanced") if numerics is None else numerics
    if scene.protocol() is not None and wants_quasistatic(scene, numerics):
        return Choice("elastic", "auto: k = 1, quasi-static: the elastic branch (no memory: "
                                 "the approach and the dwell end at the preload's equilibrium)")
    if scene.protocol() is not None:
        return Choice("bem", "auto: BEM, the one model with a test protocol (approach, dwell, "
                             "retract)")
    if scene.machine_stiffness is not None and wants_quasistatic(scene, numerics):
        return Choice("elastic", "auto: k = 1, quasi-static: the elastic branch (the "
                                 "compliant machine holds it on the same branch up to the "
                                 "load minimum)")
    if scene.machine_stiffness is not None:
        return Choice("bem", "auto: BEM, the one viscoelastic model with a compliant machine "
                             "(machine_stiffness)")
    if scene.pz_law != "none":
        return Choice("crack", f"auto: crack-front model with the process zone (pz_law "
                               f"{scene.pz_law}), the BEM's local law where its error "
                               f"exceeds pull_off_rtol")
    bem_ok = _accepts("bem", scene)
    if wants_quasistatic(scene, numerics) and bem_ok:
        return Choice("elastic", "auto: k = 1, quasi-static: the elastic branch")
    if not bem_ok:
        lo, hi = BEM_MU_RANGE
        measured = _fits()["crack"]["mu_range"][1]
        return Choice("crack", f"auto: crack-front model, the mu -> infinity limit: mu = "
                               f"{scene.mu:g} is beyond the BEM's range [{lo:g}, {hi:g}] "
                               f"(its error measured up to mu = {measured:g})")
    tol = numerics.pull_off_rtol
    for model in BY_COST[:-1]:
        err = measured_error(model, scene.mu)
        if _accepts(model, scene) and err <= tol and not (
                scene.table is not None and model in TABLE_REFUSALS):
            return Choice(model, f"auto: {NAMES[model]}, measured error at most {err:.2g} <= "
                                 f"pull_off_rtol {tol:g} at mu = {scene.mu:g}", err)
    mesh = "tip-following mesh" if wants_tip_following(scene, numerics) else "graded mesh"
    return Choice("bem", f"auto: BEM on the {mesh} (no cheaper model within pull_off_rtol "
                         f"{tol:g})")


def choose_model(scene, numerics=None) -> str:
    """The name of the model "auto" runs for ``scene`` (:func:`model_choice`)."""
    return model_choice(scene, numerics).model


#: what the reasons call each model
NAMES = {"pb": "PB estimate", "crack": "crack-front model", "bem": "BEM",
         "elastic": "elastic branch"}


def _fallback(scene, failed: Result, model: str) -> Choice | None:
    """After the BEM (or the elastic branch) failed an "auto" scene for a reason another
    model can lift (not a physical refusal): the crack-front model, the physical limit where
    the BEM cannot resolve the tip zone, with its measured error (a contact below its
    fixed-grip limit it refuses, for that physical reason); None where it cannot answer
    either (mu below its measurement)."""
    if (is_physical_refusal(failed.reason) or math.isnan(measured_error("crack", scene.mu))
            or scene.protocol() is not None or scene.machine_stiffness is not None):
        return None             # (the crack-front model refuses protocols and machines)
    return Choice("crack", f"auto: crack-front model: the {NAMES[model]} failed "
                           f"({shortened(failed.reason, 160)})")


#: model name -> simulate(scene, numerics=None) -> Result
MODELS = {"bem": _bem, "crack": simulate_crack, "pb": simulate_pb, "elastic": simulate_elastic}


def wants_quasistatic(scene, numerics) -> bool:
    """Whether a "bem" or "auto" scene is elastic and quasi-static, so that the equilibrium
    branch (:mod:`sweep.engine.quasistatic`) answers it without the hereditary machinery: k = 1,
    no process zone (a rate-dependent interface is not quasi-static), started from a0,
    stopped at the pull-off (a compliant machine holds the sphere on the same branch up to
    its load minimum: :func:`sweep.engine.quasistatic.simulate_elastic`), on
    the engine's own mesh (an explicit ``numerics.domain`` or ``exact`` asks for the
    hereditary BEM on that domain). A test protocol too: without memory, its approach and
    dwell end in the branch's equilibrium at the preload."""
    return (scene.k == 1.0 and (scene.a0 is not None or scene.protocol() is not None)
            and scene.stop == "pulloff"
            and numerics.domain is None and not numerics.exact and scene.pz_law == "none")


#: a crack row with a process zone: its difference from the BEM's local law, measured by
#: ``make pz-check`` (results/process_zone/check.json, 9 scenes at mu 5), grows with the
#: process zone's term (v/pz_v0)^pz_xi at the pull-off's crack speed: at most 0.095 of the
#: term (elastic, rates 10 and 100; 0.055 on the SLS, 0.022 on the MPL); this fraction, with
#: a quarter's margin, is added to the row's error
PROCESS_ZONE_ERROR = 0.12


def _model_error(model: str, scene, res) -> float:
    """A crack or pb row's error: :func:`measured_error` at its amplification, plus the error
    the model states itself (the nearly elastic crack-front closed form's bound), if any, and
    with a process zone :data:`PROCESS_ZONE_ERROR` times its term at the pull-off."""
    own = res.error_estimate if math.isfinite(res.error_estimate) else 0.0
    if scene.pz_law != "none" and math.isfinite(res.crack_speed) and res.crack_speed > 0:
        own += PROCESS_ZONE_ERROR * (res.crack_speed / scene.pz_v0) ** scene.pz_xi
    return measured_error(model, scene.mu, amplification(res.pull_off)) + own


#: why each model but the crack-front one refuses a scene with a process zone (``pz_law``): a
#: failed row with this reason (not a physical refusal: the crack-front model answers it)
PROCESS_ZONE_REFUSALS = {
    "elastic": "the elastic branch is quasi-static and its interface rate independent: a "
               "scene with a rate-dependent process zone (pz_law {pz_law}) runs with model "
               "bem, crack or auto",
    "pb": "the pb estimate's v-r fit was measured without a process zone: a scene with "
          "pz_law {pz_law} runs with model bem, crack or auto",
}


#: why a model refuses a scene whose material is a Prony table: a failed row with this
#: reason. The PB estimate's v-r fit (vhat = 2.887 rhat^1.171) was measured on the MPL in its
#: tau0; a table's tau0 is a unit its times are written in, and the fit's exponent made the
#: answer depend on it (16-39 % for one table written in three time units; the BEM and the
#: crack-front model agreed to 1e-9)
TABLE_REFUSALS = {
    "pb": "the pb estimate's v-r fit was measured on the MPL in its tau0, and a Prony table's "
          "time unit is arbitrary (its answer depended on it): a table runs with model "
          "crack, bem or auto",
}


#: why each model but the BEM and the elastic branch (k = 1 only: no memory) refuses a scene
#: with a test protocol: a failed row with this reason (not a physical refusal: the BEM
#: answers it; auto sends it there)
PROTOCOL_REFUSALS = {
    "crack": "the crack-front model starts from a relaxed contact and its bulk is relaxed: a "
             "test protocol (approach, dwell, retract) runs with model bem or auto",
    "pb": "the pb estimate has no loading history: a test protocol (approach, dwell, retract) "
          "runs with model bem or auto",
}


#: why each model but the BEM and the elastic branch refuses a scene with a compliant machine
#: a failed row with this reason (not a physical refusal: the BEM answers it; auto sends it
#: there)
MACHINE_REFUSALS = {
    "crack": "the crack-front model prescribes the sphere's indentation: a compliant machine "
             "(machine_stiffness) runs with model bem or auto",
    "pb": "the pb estimate's v-r fit was measured with a rigid machine: a compliant machine "
          "(machine_stiffness) runs with model bem or auto",
}


def _run(model: str, scene, numerics) -> Result:
    """``MODELS[model]``; a numerical failure is a failed result, a bug raises; a scene with
    a process zone, a protocol or a compliant machine that the model has no law for is
    refused (:data:`PROCESS_ZONE_REFUSALS`, :data:`PROTOCOL_REFUSALS`,
    :data:`MACHINE_REFUSALS`)."""
    if scene.pz_law != "none" and model in PROCESS_ZONE_REFUSALS:
        return Result(scene=scene, numerics=numerics, status="failed",
                      reason=PROCESS_ZONE_REFUSALS[model].format(pz_law=scene.pz_law))
    if scene.protocol() is not None and model in PROTOCOL_REFUSALS:
        return Result(scene=scene, numerics=numerics, status="failed",
                      reason=PROTOCOL_REFUSALS[model])
    if scene.machine_stiffness is not None and model in MACHINE_REFUSALS:
        return Result(scene=scene, numerics=numerics, status="failed",
                      reason=MACHINE_REFUSALS[model])
    if scene.table is not None and model in TABLE_REFUSALS:
        return Result(scene=scene, numerics=numerics, status="failed",
                      reason=TABLE_REFUSALS[model])
    try:
        budget.check(f"the {NAMES[model]}'s start")
        return MODELS[model](scene, numerics)
    except budget.OverBudget as exc:
        return Result(scene=scene, numerics=numerics, status="failed", reason=str(exc))
    except NUMERICAL_ERRORS as exc:   # a numerical failure is a result; a bug (TypeError, ...)
        if is_internal_error(exc):     # raises: sweep run records it as status "error"
            raise
        return Result(scene=scene, numerics=numerics, status="failed",
                      reason=f"{type(exc).__name__}: {exc}")


def simulate_model(scene, model: str = "bem", numerics=None):
    """Run ``scene`` with the named model (one of :data:`MODELS` or "auto"); the result's
    ``model_used`` says which ran and ``model_reason`` why. An "auto" scene the BEM failed
    for a reason another model can lift runs the crack-front model (:func:`_fallback`). A
    "crack" or "pb" row's ``error_estimate`` is the model's :func:`measured_error`."""
    check_choice("model", model, (*MODELS, "auto"))
    numerics = Numerics.preset("balanced") if numerics is None else numerics
    t0 = time.perf_counter()
    with budget.scene_budget(numerics.time_budget_s):
        res = _simulate_model(scene, model, numerics)
    if model == "auto":     # every model auto ran (a fallback's row had counted its own only)
        res.wall_s = time.perf_counter() - t0
    return res


#: the slowest crack speed at pull-off, in indentation speeds (rate h0), :func:`_negligible_zone`
#: screens a zone with before running the elastic branch (the branch costs 0.2-5 s; the
#: crack at the pull-off runs faster than the indentation)
NEGLIGIBLE_CRACK_SPEED = 1e-3


def _negligible_zone(scene, numerics) -> Result | None:
    """The row of an "auto" scene whose process zone is too weak to count on an elastic,
    quasi-static bulk: the elastic branch's row of the scene without the zone, the zone's
    Gent-Schultz term at ten times its crack speed added to the estimate, where that term is
    at most :data:`~sweep.engine.crack_front.NEGLIGIBLE_PROCESS_ZONE` (the crack-front
    model's own rule); else None. (Such a zone, pz_v0 = 1e20, had sent the scene to the
    hereditary BEM, whose row was unresolved at the balanced preset where the plain scene's
    was ok.)"""
    if scene.pz_law == "none":
        return None
    plain = dataclasses.replace(scene, pz_law="none", pz_v0=None, pz_xi=None)
    indentation_speed = scene.rate * units.h0_hat(scene.mu)
    if not wants_quasistatic(plain, numerics) or not (
            10.0 * NEGLIGIBLE_CRACK_SPEED * indentation_speed / scene.pz_v0) ** scene.pz_xi \
            <= NEGLIGIBLE_PROCESS_ZONE:
        return None      # (a zone that counts even at a crack this slow: no branch to run)
    res = _run("elastic", plain, numerics)
    term = negligible_zone_term(scene, res.crack_speed)
    if not res.ok or not term <= NEGLIGIBLE_PROCESS_ZONE:
        return None
    res.scene = scene
    res.error_estimate = float(res.error_estimate) + term
    note = (f"the process zone's term (v/pz_v0)^pz_xi at ten times the crack speed, {term:.2g}, "
            f"is negligible: the scene without it, the term added to error_estimate")
    res.reason = f"{res.reason}; {note}" if res.reason else note
    res.model_used = "elastic"
    res.model_reason = "auto: k = 1, quasi-static, a negligible process zone: the elastic branch"
    return res


def _simulate_model(scene, model: str, numerics) -> Result:
    """:func:`simulate_model` inside the scene's time budget (:mod:`sweep.engine.budget`):
    every model it runs, first or as a fallback, shares the one deadline."""
    if model == "auto":
        negligible = _negligible_zone(scene, numerics)
        if negligible is not None:
            return negligible
        choice = model_choice(scene, numerics)
    elif model == "bem" and wants_quasistatic(scene, numerics):
        choice = Choice("elastic", "bem: k = 1, quasi-static: the elastic branch")
    else:
        choice = Choice(model, f"{model}: asked for")
    ran: dict[str, Result] = {}

    def run(name: str) -> Result:     # each model at most once (a cheaper try is reused)
        if name not in ran:
            ran[name] = _run(name, scene, numerics)
            if ran[name].ok and name in ("crack", "pb"):
                ran[name].error_estimate = _model_error(name, scene, ran[name])
                if math.isnan(ran[name].error_estimate):     # below the measured Tabor range
                    lo = _fits()[name]["mu_range"][0]
                    note = (f"the {NAMES[name]}'s error is not measured below mu = {lo:g} "
                            f"(error_estimate NaN): the BEM (model bem or auto) answers this "
                            f"scene with its own")
                    ran[name].reason = (f"{ran[name].reason}; {note}" if ran[name].reason
                                        else note)
        return ran[name]

    res = run(choice.model)
    if (choice.model == "elastic" and model in ("bem", "auto") and scene.protocol() is not None
            and res.status == "failed" and budget.remaining() > 0):
        # the branch's protocol is parametrized by the contact radius from JKR's first
        # contact, which a DMT-like contact (mu 0.01, a small preload) need not reach: the
        # BEM marches it
        choice = Choice("bem", f"{model}: BEM: the elastic branch failed the test protocol "
                               f"({shortened(res.reason, 120)})")
        res = run("bem")
    if model == "auto" and choice.model in ("crack", "pb") and scene.mu <= BEM_MU_RANGE[1] \
            and not res.error_estimate <= numerics.pull_off_rtol:
        miss = (f"auto: BEM: the {NAMES[choice.model]}'s measured error at its amplification "
                f"{amplification(res.pull_off):.3g}, {res.error_estimate:.2g}, exceeds "
                f"pull_off_rtol {numerics.pull_off_rtol:g}" if res.ok else
                f"auto: BEM: the {NAMES[choice.model]} failed ({shortened(res.reason, 120)})")
        choice, res = Choice("bem", miss), run("bem")
    if model == "auto" and choice.model in ("bem", "elastic") and res.status == "failed":
        fallback = _fallback(scene, res, choice.model)
        if fallback is not None and budget.remaining() > 0:   # the scene's time left
            crack = run("crack")
            if unresolved(res) and crack.ok and not crack.error_estimate < res.error_estimate:
                # an unresolved row is nearer than the crack-front model's measured error:
                # it stays (a process zone at mu 3.24 swapped a BEM row estimated 0.041 for
                # a crack-front row "ok" at 4.65)
                res.reason += (f"; the crack-front model's measured error, "
                               f"{crack.error_estimate:.2g}, is larger")
            else:
                choice, res = fallback, crack
    res.model_used = choice.model
    res.model_reason = choice.reason
    if choice.model == "crack" and res.ok and model == "auto":
        tol = numerics.pull_off_rtol
        over = f" (above pull_off_rtol {tol:g})" if res.error_estimate > tol else ""
        res.model_reason += f"; measured error {res.error_estimate:.2g}{over}"
    return res


def simulate(scene: Scene, numerics: Numerics | None = None) -> Result:
    """Simulate one scene with the model it asks for: the one entry for one scene.

    ``sweep.simulate``, ``sweep scene`` and every scene of ``sweep run`` go through here, so
    the three can never disagree. ``scene.model`` picks the model (:data:`MODELS`, or
    "auto"); a "bem" scene runs on the graded mesh, on the tip-following mesh where the
    graded mesh's crack band would exceed ``numerics.max_nodes``, or on the quasi-static
    elastic branch when it is elastic and quasi-static (:func:`simulate_model`).

    Parameters
    ----------
    scene : Scene
        Physics: material (n, k), Tabor parameter, initial state, unloading rate, model
        (docs/design.md section 2 units).
    numerics : Numerics, optional
        Discretization and tolerances; default ``Numerics.preset("balanced")``.

    Returns
    -------
    Result
        ``model_used`` says which model ran; a numerical failure is ``status="failed"``
        with a reason, never an exception. A programming error (TypeError, IndexError, ...:
        :func:`sweep.errors.is_internal_error`) raises: a bug is not a result.
    """
    if not isinstance(scene, Scene):
        raise TypeError("scene must be a sweep.Scene")
    if numerics is not None and not isinstance(numerics, Numerics):
        raise TypeError("numerics must be a sweep.Numerics")
    return simulate_model(scene, scene.model, numerics)


#: the name sweeps used before :func:`simulate` was the package's front door
simulate_scene = simulate
