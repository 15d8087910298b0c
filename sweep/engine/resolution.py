"""The error indicator of a BEM result: the error expected from the crack band's resolution,
and where that is not well below the tolerance, the pull-off change on a mesh of half the
resolution (a result whose indicator exceeds ``numerics.pull_off_rtol`` is not ``ok``).

Used alike by the graded mesh (:mod:`sweep.engine.bem`) and the tip-following mesh
(:mod:`sweep.engine.tip_following`).
"""
from __future__ import annotations

import dataclasses
import math
from typing import Callable

from ..scene import Numerics, Result

#: the resolution error model, K (spacing/length)^2 (see :func:`resolution_error`) ...
RESOLUTION_ERROR_K = 0.3
#: ... decides alone while below this fraction of numerics.pull_off_rtol; above it the
#: scene is solved again at half the resolution and the pull-off change decides
CHECK_FRACTION = 0.25


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
    (spacing/length)^2, with ``spacing`` the fine node spacing and ``length`` the zone it
    resolves (both a_ref).

    The bound of the measured convergence (README, "Speed and accuracy"): on the reference
    scenes A, D, F the pull-off error times (l0/spacing)^2 stays below 0.22 from 6 to 40
    spacings per l0.
    """
    return RESOLUTION_ERROR_K * (spacing / length) ** 2


def coarser(numerics: Numerics) -> Numerics:
    """The numerics of the error indicator's cheaper solve: half the mesh resolution
    (half the band resolution, or half the nodes), no coarse-mesh refusal."""
    if numerics.nodes is not None or numerics.mesh == "uniform":
        return dataclasses.replace(numerics, nodes=max(numerics.uniform_nodes // 2, 20),
                                   zone_nodes=0.0)
    return dataclasses.replace(numerics, band_resolution=max(numerics.band_resolution / 2, 2.0),
                               zone_nodes=0.0)


def check_resolution(res: Result, coarse: Result) -> None:
    """Set the error estimate of ``res`` from the half-resolution solve ``coarse``; not
    ``ok`` when it exceeds the tolerance (or the cheaper solve failed)."""
    tol = res.numerics.pull_off_rtol
    if not coarse.ok:
        res.error_estimate = math.inf
        res.status = "failed"
        res.reason = (f"unresolved: the check on a mesh of half the resolution failed "
                      f"({coarse.reason}); {refine_advice(res.numerics)}")
        return
    res.error_estimate = abs(res.pull_off - coarse.pull_off) / res.pull_off
    if res.error_estimate > tol:
        res.status = "failed"
        res.reason = (f"unresolved: the pull-off moves by {res.error_estimate:.2g} (> pull_off_rtol "
                      f"= {tol:g}) on a mesh of half the resolution ({coarse.pull_off:.5g} vs "
                      f"{res.pull_off:.5g}); {refine_advice(res.numerics)}")


def estimate_error(res: Result, length: float, solve: Callable[[Numerics], Result]) -> None:
    """The error indicator of an ``ok`` result, in place: :func:`resolution_error` of its
    spacing against ``length`` (a_ref), and where that exceeds CHECK_FRACTION
    pull_off_rtol, :func:`check_resolution` against ``solve(coarser(numerics))``.
    Nothing is done when ``res`` failed or ``pull_off_rtol`` is 0."""
    tol = res.numerics.pull_off_rtol
    if not res.ok or tol <= 0:
        return
    res.error_estimate = resolution_error(res.spacing, length)
    if res.error_estimate > CHECK_FRACTION * tol:
        check_resolution(res, solve(coarser(res.numerics)))
