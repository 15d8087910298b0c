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
         edge opens with the Persson-Brener Gamma(v) of the scene's spectrum
pb       the paper's closed-form estimate (:func:`pb_estimate`): the crack speed at pull-off
         from the paper's fit vhat = 2.887 rhat_PB^1.171, Gamma_PB at that speed, and the
         load-control JKR pull-off with it, P = 1.5 Gamma_PB
elastic  the quasi-static elastic branch (:func:`sweep.engine.quasistatic.simulate_elastic`), no
         hereditary machinery: k = 1 scenes over the whole Tabor range 0.01-100; "bem" and
         "auto" scenes that are elastic and quasi-static run it (:func:`wants_quasistatic`)
auto     the cheapest model the scene allows (:func:`choose_model`): the BEM where the mesh that
         resolves l0 fits the numerics' node count, the crack-front model otherwise and beyond
         the BEM's Tabor range (mu > 100: its reason says so, with its measured difference)
=======  ======================================================================================

Every simulate function takes ``(scene, numerics=None)`` and returns a :class:`sweep.Result`;
the store and the analysis do not care which ran.
"""
from __future__ import annotations

import dataclasses
import math
import time

from .. import units
from ..errors import NUMERICAL_ERRORS, check_choice, check_positive, is_internal_error
from ..scene import Numerics, Result, Scene
from ..theory import paper_v_vs_r_fit, pb_gamma_eff, pb_gamma_eff_spectrum
from . import bem
from .crack_front import simulate_crack
from .mesh import scene_mesh
from .problem import BEM_MU_RANGE, derive
from .quasistatic import simulate_elastic
from .tip_following import simulate_tip_following

__all__ = ["MODELS", "simulate", "pb_estimate", "simulate_pb", "simulate_model",
           "simulate_scene", "choose_model", "bem_nodes_needed", "bem_node_budget",
           "wants_quasistatic", "wants_tip_following"]


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
    material : {"mpl", "sls"}
    prefactor, exponent : float
        Constants of the v-r fit.

    Returns
    -------
    dict
        ``pull_off`` (pi dg R), ``vhat`` (v tau0/l0), ``crack_speed`` (a_ref/tau0),
        ``gamma`` (Gamma/dg), ``rhat_pb``.
    """
    material = check_choice("material", material, ("mpl", "sls"))
    rhat = units.rhat_pb(rate, mu)
    vhat = paper_v_vs_r_fit(rhat, prefactor, exponent)
    if material == "mpl":
        gamma = pb_gamma_eff(n, k, vhat)
    else:
        gamma = pb_gamma_eff_spectrum([1.0], [1.0], k, vhat)
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
    numerics = Numerics.preset("balanced") if numerics is None else numerics
    if wants_tip_following(scene, numerics):
        return simulate_tip_following(scene, numerics)
    return bem.simulate(scene, numerics)


def wants_tip_following(scene, numerics) -> bool:
    """Whether a BEM scene runs on the tip-following mesh (:mod:`sweep.engine.tip_following`):
    a graded mesh sized from the band resolution (``nodes`` unset, not ``exact``) whose
    fixed crack band would need more than ``numerics.max_nodes`` nodes (large mu or a0)."""
    return (numerics.mesh == "graded" and numerics.nodes is None and not numerics.exact
            and bem_nodes_needed(scene, numerics) > numerics.max_nodes)


def bem_nodes_needed(scene, numerics=None) -> int:
    """Nodes the BEM needs for ``scene``.

    Uniform mesh: its automatic (or given) domain over the spacing at which the process zone
    ``l0 = 1.693/mu^2`` spans ``numerics.zone_nodes`` spacings. Graded mesh: the nodes of
    the mesh the solver would build (:func:`sweep.engine.mesh.scene_mesh`, sized from the band
    resolution).
    """
    numerics = Numerics.preset("balanced") if numerics is None else numerics
    s = derive(scene, numerics)
    if numerics.mesh == "uniform":
        return int(math.ceil(s.domain * numerics.zone_nodes / s.tip_zone)) + 1
    mesh = scene_mesh(dataclasses.replace(numerics, nodes=None), s.tip_zone, s.a0_estimate,
                      s.domain, pull_off_only=scene.stop == "pulloff")
    return mesh.nodes


def bem_node_budget(numerics) -> int:
    """The most nodes ``numerics`` lets the BEM use: ``nodes`` (uniform) or ``max_nodes``."""
    return numerics.uniform_nodes if numerics.mesh == "uniform" else numerics.max_nodes


def choose_model(scene, numerics=None) -> str:
    """The model "auto" picks: "crack" beyond the BEM's Tabor range (:data:`BEM_MU_RANGE`:
    the crack-front model is the mu -> infinity limit), else "bem" if its mesh fits the node
    budget, else "crack"."""
    numerics = Numerics.preset("balanced") if numerics is None else numerics
    if not BEM_MU_RANGE[0] <= scene.mu <= BEM_MU_RANGE[1]:
        return "crack"
    return "bem" if bem_nodes_needed(scene, numerics) <= bem_node_budget(numerics) else "crack"


#: the crack-front model's pull-off against the BEM's at the largest mu measured
#: (results/agreement/agreement.md, ``make agreement``: n = 0.8, k = 0.1, a0 = 3,
#: rate 10^2.5): (mu, crack / BEM - 1)
CRACK_VS_BEM = ((10.0, -0.009), (15.0, 0.026))


def beyond_bem_note(scene) -> str:
    """The reason an "auto" row run by the crack-front model beyond the BEM's Tabor range
    carries: which model ran, why, and its measured difference from the BEM."""
    lo, hi = BEM_MU_RANGE
    measured = " and ".join(f"{d * 100:+.1f} % at mu = {mu:g}" for mu, d in CRACK_VS_BEM)
    return (f"crack-front model (the mu -> infinity limit): mu = {scene.mu:g} is beyond the "
            f"BEM's range [{lo:g}, {hi:g}]; against the BEM its pull-off differed by "
            f"{measured} (n = 0.8, k = 0.1, a0 = 3, rate 316; results/agreement), not "
            f"measured at larger mu")


#: model name -> simulate(scene, numerics=None) -> Result
MODELS = {"bem": _bem, "crack": simulate_crack, "pb": simulate_pb, "elastic": simulate_elastic}


def wants_quasistatic(scene, numerics) -> bool:
    """Whether a "bem" or "auto" scene is elastic and quasi-static, so that the equilibrium
    branch (:mod:`sweep.engine.quasistatic`) answers it without the hereditary machinery: k = 1,
    started from a0, stopped at the pull-off, on the engine's own mesh (an explicit
    ``numerics.domain`` or ``exact`` asks for the hereditary BEM on that domain)."""
    return (scene.k == 1.0 and scene.a0 is not None and scene.stop == "pulloff"
            and numerics.domain is None and not numerics.exact)


def simulate_model(scene, model: str = "bem", numerics=None):
    """Run ``scene`` with the named model (one of :data:`MODELS` or "auto"); the result's
    ``model_used`` says which ran."""
    check_choice("model", model, (*MODELS, "auto"))
    numerics = Numerics.preset("balanced") if numerics is None else numerics
    note = ""
    if model in ("bem", "auto") and wants_quasistatic(scene, numerics):
        model = "elastic"
    elif model == "auto":
        model = choose_model(scene, numerics)
        if model == "crack" and scene.mu > BEM_MU_RANGE[1]:
            note = beyond_bem_note(scene)
    try:
        res = MODELS[model](scene, numerics)
    except NUMERICAL_ERRORS as exc:   # a numerical failure is a result; a bug (TypeError, ...)
        if is_internal_error(exc):     # raises: sweep run records it as status "error"
            raise
        res = Result(scene=scene, numerics=numerics, status="failed",
                     reason=f"{type(exc).__name__}: {exc}")
    res.model_used = model
    if note:
        res.reason = f"{res.reason}; {note}" if res.reason else note
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
