"""A step held at a load (kernels.protocol.newton_at_load): the gap and the indentation solved
together must zero the residual numpy computes at the indentation found, carry the load
asked for, and be the state the ordinary Newton solve finds at that indentation."""
import numpy as np
import pytest

from sweep.engine.initial import ElasticSolver, relaxed_state
from sweep.engine.mesh import uniform_mesh
from sweep.engine.problem import lj_constants
from sweep.kernels import solve as ks
from sweep.kernels.interface import lennard_jones, lj_traction_and_stiffness
from sweep.kernels.protocol import newton_at_load

N = 120
TOL = 1e-10        # units of h0


def _step():
    """One unloading-like step from the relaxed elastic state at delta = 1 (C_eff < 1, a
    history vector), as tests/kernels/test_newton.py makes it."""
    mesh = uniform_mesh(N, 3.0)
    A, r = np.array(mesh.influence), np.asarray(mesh.r)
    h0, c = lj_constants(3.24)
    el = ElasticSolver(A, r, h0, c, 1e-10)
    h_start, _ = relaxed_state(el, delta0=1.0)
    return A, r, h0, c, h_start, np.asarray(mesh.load_weights)


def _load(h, h0, c, wP):
    sig, d = np.empty(h.size), np.empty(h.size)
    lj_traction_and_stiffness(h, h0, c, sig, d)
    return 2.0 * np.pi * wP @ sig, sig


@pytest.mark.parametrize("extra", [0.3, -0.2])
def test_the_held_step_carries_the_load_at_the_indentation_it_found(extra):
    A, r, h0, c, h_start, wP = _step()
    ceff, H = 0.8, -0.05 * np.exp(-r)
    delta = 1.0
    g = -delta + h0 + 0.5 * r ** 2
    force = _load(h_start, h0, c, wP)[0] + extra
    h = h_start.copy()
    cache, stats = ks.new_jacobian_cache(N), np.zeros(ks.N_STATS, np.int64)
    law = lennard_jones(h0, c, N)
    ok, shift = newton_at_load(h, g, A, wP, ceff, H, law, force,
                               np.array([TOL * h0, 1e-9 * abs(force)]), 40, cache, stats)
    assert ok
    assert np.sign(shift) == np.sign(extra)           # more load, more indentation
    P, sig = _load(h, h0, c, wP)
    assert abs(P - force) <= 1e-9 * abs(force)
    g_found = -(delta + shift) + h0 + 0.5 * r ** 2
    assert np.max(np.abs(h - g_found - A @ (ceff * sig - H))) <= TOL * h0
    # the ordinary solve at that indentation finds the same state
    h_plain = h_start.copy()
    assert ks.newton(h_plain, g_found, A, ceff, H, law, TOL * h0, 40,
                     ks.new_jacobian_cache(N), np.zeros(ks.N_STATS, np.int64))
    assert np.max(np.abs(h_plain - h)) <= 1e-6 * h0

