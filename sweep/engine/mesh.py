"""Radial meshes of the half-space surface and their cached influence matrices.

Two kinds (``Numerics.mesh``), nodes in a_ref units with r_0 = 0:

* ``"uniform"``: ``nodes`` nodes at spacing domain / (nodes - 1);
* ``"graded"``: uniform fine spacing across the *crack band* [band_lo, band_hi] that the
  crack tip sweeps while unloading (from a little outside the initial contact radius a0
  down to below the pull-off radius), spacings growing geometrically by ``grading`` from
  the band inward to r = 0 (deep inside the compressed contact) and outward to the domain
  edge (the far Lennard-Jones tail). The fine spacing is the tip zone (the process zone
  l0 = 1.693/mu^2, or sqrt(h0) on the DMT side: :func:`sweep.engine.problem.tip_zone`) divided
  by ``band_resolution``, or the one that gives exactly ``nodes``
  nodes when a node count is requested.

The influence matrix of a mesh is assembled once per process (:func:`influence`); a
uniform mesh scales the cached unit-spacing matrix.
"""
from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .. import kernels
from ..kernels.influence import (assemble_nodes, combine_lattice_hats, grow_unit,
                               load_weights_nodes)

from . import diskcache

#: the crack band reaches this fraction of a0 inward (pull-off radii measured on the
#: reference scenes are 0.42-0.53 a0; the elastic limit is 1.145 a_ref) ...
BAND_INNER_FRACTION = 0.3
#: ... and this many process zones l0 beyond each end (the cohesive zone around the tip)
BAND_MARGIN_ZONES = 4.0
#: the outer band edge lies this factor outside the estimated initial contact radius, and
#: at least at BAND_OUTER_MIN: from a0 below the elastic pull-off radius 1.145 the tip first
#: advances (to 1.10 from a0 = 1 at mu = 10)
BAND_OUTER_FACTOR = 1.05
BAND_OUTER_MIN = 1.3


@dataclass(frozen=True)
class Mesh:
    """Node positions of one radial mesh (a_ref units) and where its fine band lies.

    Attributes
    ----------
    r : ndarray
        Node positions, r[0] = 0, increasing; read-only.
    kind : {"uniform", "graded"}
    spacing : float
        The fine spacing (the only spacing of a uniform mesh).
    band : (float, float)
        [lo, hi] of the uniformly fine crack band (the whole mesh when uniform).
    key : tuple
        Hashable parameters that determine ``r`` in units of ``spacing`` (the influence
        matrix of the mesh is ``spacing`` times a matrix cached under this key).
    lattice : ndarray of int
        r / spacing: every node lies on the lattice of the fine spacing.
    """

    r: np.ndarray
    kind: str
    spacing: float
    band: tuple
    key: tuple
    lattice: np.ndarray

    @property
    def nodes(self) -> int:
        return int(self.r.size)

    @property
    def domain(self) -> float:
        return float(self.r[-1])

    @property
    def load_weights(self) -> np.ndarray:
        """w_j with P = 2 pi w . sigma (exact for piecewise-linear traction)."""
        return _load_weights(self)

    @property
    def influence(self) -> np.ndarray:
        """The influence matrix (read-only, cached per process)."""
        return influence(self)

    @property
    def tail_rise(self) -> float:
        """(r_end^2 - r_last^2)/2: the rise of the rigid gap from the last node to the end of
        its hat, r_end = 2 r_last - r_(last-1) (the last node's hat is a full triangle,
        :func:`sweep.kernels.influence.load_weights_nodes`). Beyond r_end the load adds the
        Lennard-Jones attraction of the gap continued rigidly, from h_end = h_last +
        tail_rise (:func:`sweep.kernels.solve.load`, :func:`sweep.kernels.interface.tail_load`)."""
        r_last, r_end = float(self.r[-1]), 2.0 * float(self.r[-1]) - float(self.r[-2])
        return 0.5 * (r_end * r_end - r_last * r_last)


def uniform_mesh(nodes: int, domain: float) -> Mesh:
    """``nodes`` nodes from 0 to ``domain`` (a_ref units)."""
    nodes = int(nodes)
    spacing = domain / (nodes - 1)
    r = np.arange(nodes) * spacing
    r.setflags(write=False)
    idx = np.arange(nodes)
    idx.setflags(write=False)
    return Mesh(r, "uniform", spacing, (0.0, float(domain)), ("uniform", nodes), idx)


def _graded_steps(length: int, ratio: float) -> list:
    """Integer element lengths growing like ratio^k (k = 1, 2, ...) that sum to ``length``.

    Lengths are floor(ratio^k), at least 1 and never decreasing; the remainder goes to the
    last element (or a new one when it is at least half as long as the previous).
    """
    steps, total, k = [], 0, 1
    while True:
        m = max(1, int(math.floor(ratio ** k)))
        if steps:
            m = max(m, steps[-1])
        if total + m > length:
            rest = length - total
            if rest > 0:
                if steps and rest < 0.5 * steps[-1]:
                    steps[-1] += rest
                else:
                    steps.append(rest)
            return steps
        steps.append(m)
        total += m
        k += 1


def _graded_lattice(n_domain: int, lo: int, hi: int, ratio: float) -> np.ndarray:
    """Lattice indices: every point of [lo, hi], graded steps inward to 0 and out to n_domain."""
    inner = np.cumsum(_graded_steps(lo, ratio)) if lo > 0 else np.zeros(0, np.int64)
    outer = np.cumsum(_graded_steps(n_domain - hi, ratio)) if n_domain > hi else np.zeros(0, np.int64)
    left = (lo - inner)[::-1]                   # nodes below the band, from 0 up
    return np.concatenate([left, np.arange(lo, hi + 1), hi + outer]).astype(np.int64)


def graded_mesh(domain: float, band: tuple, spacing: float, grading: float) -> Mesh:
    """Fine ``spacing`` across ``band`` = (lo, hi), element lengths growing by about
    ``grading`` per element outside (inward to r = 0 and outward to ``domain``).

    Every node lies on the lattice of the fine spacing (element lengths are integer
    multiples of it), so the influence matrix is an exact combination of the cached
    unit-spacing one; the band ends and the domain are rounded outward to the lattice.
    """
    n_domain = int(math.ceil(domain / spacing - 1e-9))
    lo = max(int(math.floor(band[0] / spacing + 1e-9)), 0)
    hi = min(int(math.ceil(band[1] / spacing - 1e-9)), n_domain)
    idx = _graded_lattice(n_domain, lo, hi, float(grading))
    r = idx * float(spacing)
    r.setflags(write=False)
    idx.setflags(write=False)
    return Mesh(r, "graded", float(spacing), (lo * spacing, hi * spacing),
                ("graded", n_domain, lo, hi, float(grading)), idx)


def graded_mesh_with_nodes(nodes: int, domain: float, band: tuple, grading: float) -> Mesh:
    """The graded mesh of ``domain`` and ``band`` with about ``nodes`` nodes (never more):
    the fine spacing found by bisection."""
    lo_s, hi_s = domain / (50.0 * nodes), float(domain) / 2.0
    mesh = graded_mesh(domain, band, hi_s, grading)
    for _ in range(60):
        mid = math.sqrt(lo_s * hi_s)
        m = graded_mesh(domain, band, mid, grading)
        if m.nodes > nodes:
            lo_s = mid
        else:
            hi_s, mesh = mid, m
            if m.nodes == nodes:
                break
    return mesh


def crack_band(a0: float, l0: float, pull_off_only: bool = True) -> tuple[float, float]:
    """[lo, hi] of the radii the crack tip sweeps from the initial contact radius ``a0``.

    ``pull_off_only=False`` (following the curve to separation) reaches down to r = 0.
    """
    hi = max(BAND_OUTER_FACTOR * a0, BAND_OUTER_MIN) + BAND_MARGIN_ZONES * l0
    lo = BAND_INNER_FRACTION * a0 - BAND_MARGIN_ZONES * l0 if pull_off_only else 0.0
    return max(lo, 0.0), hi


#: the cached unit-spacing matrix grows in multiples of this many nodes
UNIT_BLOCK = 256
#: a graded mesh whose lattice is wider than this many fine spacings (a fine band at large
#: mu: 2.4e5 at mu = 100) has its influence matrix assembled on its own nodes
#: (kernels.influence.assemble_nodes, 0.13 s for 700 nodes) rather than combined from the
#: unit-spacing matrix of the whole lattice, whose assembly costs about 0.28 us per entry
#: (1.2 s at 2048; one run each, 2026-11-26; it was 3.5 us when this bound was set); it is
#: assembled once per machine (see unit_influence)
LATTICE_MAX_WIDTH = 2048
_UNIT = [np.zeros((0, 0))]
_MESH_CACHE: dict = {}
_MESH_CACHE_SIZE = 32


def set_mesh_cache_size(size: int) -> int:
    """Keep up to ``size`` meshes' influence matrices in this process (32 by default; the
    oldest is dropped first); returns the previous size. A benchmark timing many numerics in
    rounds keeps them all."""
    global _MESH_CACHE_SIZE
    previous, _MESH_CACHE_SIZE = _MESH_CACHE_SIZE, int(size)
    return previous


def clear_mesh_cache() -> None:
    """Forget this process's influence matrices of meshes (not the unit matrix)."""
    _MESH_CACHE.clear()


def set_unit_influence(matrix=None) -> np.ndarray:
    """Replace this process's in-memory unit-spacing influence matrix (``None``: empty, so the
    next mesh reads it from disk or assembles it, as a cold process does); returns the
    previous one, to be put back."""
    previous = _UNIT[0]
    _UNIT[0] = np.zeros((0, 0)) if matrix is None else matrix
    return previous


def _unit_files(d: Path) -> list:
    """[(size, path)] of the cached unit matrices of this kernels/influence.py, largest
    first."""
    tag = diskcache.source_tag(kernels.influence.__file__)
    out = []
    for p in d.glob(f"unit_influence_{tag}_*.npy"):
        try:
            out.append((int(p.stem.rsplit("_", 1)[1]), p))
        except ValueError:
            continue
    return sorted(out, reverse=True)


def _save_unit(d: Path, A: np.ndarray) -> None:
    """Cache ``A``; the smaller cached matrices, its leading blocks, are removed."""
    tag = diskcache.source_tag(kernels.influence.__file__)
    if diskcache.save(d / f"unit_influence_{tag}_{A.shape[0]}.npy", {"a": A}):
        for size, p in _unit_files(d):
            if size < A.shape[0]:
                p.unlink(missing_ok=True)


def unit_influence(N: int) -> np.ndarray:
    """The leading N x N block of the unit-spacing influence matrix (read-only).

    Its entries do not depend on the matrix size (the last node has a full hat), so one
    matrix, grown in blocks of UNIT_BLOCK nodes (only the new rows and columns are
    assembled), serves every mesh of the process. It is kept on disk too (:mod:`sweep.engine.diskcache`,
    memory-mapped, so that the workers of a sweep share one copy and a new process does not
    assemble it again); the file name carries a hash of kernels/influence.py.
    """
    if _UNIT[0].shape[0] < N:
        size = UNIT_BLOCK * int(math.ceil(N / UNIT_BLOCK))
        d = diskcache.cache_dir()
        start = _UNIT[0]
        if d is not None:
            for cached, path in _unit_files(d):
                A = diskcache.load(path, mmap=True)
                if A is None or A.shape != (cached, cached) or A.dtype != np.float64:
                    continue
                if cached >= size:
                    _UNIT[0] = A
                    return A[:N, :N]
                if cached > start.shape[0]:
                    start = A
                break
        A = grow_unit(start, size)
        A.setflags(write=False)
        _UNIT[0] = A
        if d is not None:
            _save_unit(d, A)
    return _UNIT[0][:N, :N]


def influence(mesh: Mesh) -> np.ndarray:
    """The influence matrix of ``mesh`` (read-only), from the cached unit-spacing matrix."""
    A1 = _MESH_CACHE.get(mesh.key)
    if A1 is None:
        idx = mesh.lattice
        if mesh.kind == "uniform":
            A1 = unit_influence(mesh.nodes)
        elif 2 * idx[-1] - idx[-2] + 1 > LATTICE_MAX_WIDTH:
            A1 = assemble_nodes(idx.astype(float))
        else:
            width = int(2 * idx[-1] - idx[-2]) + 1
            A1 = combine_lattice_hats(np.ascontiguousarray(unit_influence(width)[idx, :]),
                                      np.ascontiguousarray(idx))
        if len(_MESH_CACHE) >= _MESH_CACHE_SIZE:
            _MESH_CACHE.pop(next(iter(_MESH_CACHE)))
        _MESH_CACHE[mesh.key] = A1
    A = A1 * mesh.spacing
    A.setflags(write=False)
    return A


def _load_weights(mesh: Mesh) -> np.ndarray:
    return load_weights_nodes(np.ascontiguousarray(mesh.r))


def scene_mesh(numerics, l0: float, a0_estimate: float, domain: float,
               pull_off_only: bool = True, band: tuple | None = None) -> Mesh:
    """The mesh of a scene: ``numerics.mesh`` over ``domain`` (a_ref units).

    Graded: the crack band from the estimated initial contact radius ``a0_estimate`` and
    the process zone ``l0`` (or the given ``band``), fine spacing l0/band_resolution or
    the one that gives ``numerics.nodes`` nodes.
    """
    if numerics.mesh == "uniform":
        return uniform_mesh(numerics.uniform_nodes, domain)
    if band is None:
        band = crack_band(a0_estimate, l0, pull_off_only)
    if numerics.nodes is not None:
        return graded_mesh_with_nodes(numerics.nodes, domain, band, numerics.grading)
    return graded_mesh(domain, band, l0 / numerics.band_resolution, numerics.grading)


# -- the tip-following window (sweep.engine.tip_following) ---------------------------------

#: room for the tip in its direction of motion, in tip zones (Scales.tip_zone: the process
#: zone l0 at mu >= 1.83; the tip moves this far, less TIP_MARGIN_ZONES, between two meshes)
WINDOW_AHEAD_ZONES = 16.0
#: fine region behind the tip (the cohesive zone, a few l0, and the recent wake), tip zones
WINDOW_BEHIND_ZONES = 8.0


def tip_window(tip: float, zone: float, ahead: float = WINDOW_AHEAD_ZONES,
               behind: float = WINDOW_BEHIND_ZONES, direction: int = -1) -> tuple[float, float]:
    """The fine window (a_ref radii) for a crack tip at ``tip`` moving inward
    (``direction`` -1, the contact shrinks) or outward (+1): ``ahead`` tip zones ``zone`` of
    room in the direction of motion, ``behind`` zones on the other side."""
    if direction < 0:
        lo, hi = tip - ahead * zone, tip + behind * zone
    else:
        lo, hi = tip - behind * zone, tip + ahead * zone
    return max(lo, 0.0), hi


def band_nodes(numerics, zone: float, a0_estimate: float, domain: float,
               pull_off_only: bool = True) -> int:
    """Nodes of a scene's graded mesh sized from the band resolution (``numerics.nodes``
    ignored): its fixed crack band from ``a0_estimate`` for the tip zone ``zone``, graded
    outside it to ``domain`` (a_ref). What one time step costs on the graded mesh, against
    :func:`window_nodes`, and what ``numerics.max_nodes`` bounds."""
    return scene_mesh(dataclasses.replace(numerics, nodes=None), zone, a0_estimate, domain,
                      pull_off_only=pull_off_only).nodes


def window_nodes(numerics, zone: float, a0_estimate: float, domain: float,
                 ahead: float = WINDOW_AHEAD_ZONES, behind: float = WINDOW_BEHIND_ZONES) -> int:
    """Nodes of a scene's first tip-following mesh: the window at the estimated initial
    contact radius ``a0_estimate`` for the tip zone ``zone``, graded outside it to
    ``domain`` (a_ref), at the fine spacing of ``numerics`` (what one time step costs on
    that mesh, against the graded mesh's fixed band, :func:`band_nodes`)."""
    num = dataclasses.replace(numerics, mesh="graded", nodes=None, exact=False)
    return scene_mesh(num, zone, a0_estimate, domain,
                      band=tip_window(a0_estimate, zone, ahead, behind)).nodes
