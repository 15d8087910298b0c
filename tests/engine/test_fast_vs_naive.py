"""`simulate` against the slow reference solver tests/naive.py on small meshes.

Same model, same mesh (mu = 1, N = 80, spacing 0.05, the paper's full last triangle), the
same Lennard-Jones tail beyond the mesh in the load, same indentation steps (da_max off), written independently (dense quadrature matrix and dense
Newton in numpy against the Numba kernels). Pull-off, radius and the whole load history are
compared:

* ``exact=True`` (hereditary integral summed directly in both): the same discrete equations,
  so the difference is the Newton tolerance (1e-10): measured 2e-11 on the pull-off and
  9e-10 on P(t) (with the tail, session 49; 1e-11 and 5e-10 before); tolerances 1e-9 and 1e-8.
* Prony recursion (the production path) at ``prony_rtol``: the series errs by at most rtol on
  Chat, so the load errs by about rtol times the load. Measured: pull-off within 0.13 rtol,
  P(t) within 0.39 rtol max|P| (rtol = 1e-4 and 1e-6; session 49, with the tail);
  tolerances rtol and 2 rtol max|P|.
"""
from __future__ import annotations

import numpy as np
import pytest

from sweep import Numerics, Scene
from sweep.engine.bem import simulate  # the BEM on the graded mesh (not the model dispatch)
from tests import naive as nv

N, DR, DELTA0, STEP = 80, 0.05, 2.0, 0.1
CASES = [(0.6, 0.2, 1.0), (1.6, 0.1, 10.0), (0.4, 0.1, 3.0)]


@pytest.fixture(scope="module")
def references():
    return {(n, k, rate): nv.naive_unload(n, k, 1.0, DELTA0, rate, N, DR, STEP, tail="full",
                                          lj_tail=True)
            for n, k, rate in CASES}


def _engine(n, k, rate, **num):
    return simulate(Scene(n=n, k=k, mu=1.0, delta0=DELTA0, rate=rate),
                    Numerics(nodes=N, domain=(N - 1) * DR, step=STEP, da_max=1e6, tol=1e-10,
                             **num))


def _common(res, ref):
    m = min(res.steps, ref["steps"]) + 1
    np.testing.assert_allclose(res.trajectory["t"][:m], ref["t"][:m], rtol=1e-12)
    return res.trajectory["P"][:m], ref["P"][:m]


@pytest.mark.parametrize("case", CASES)
def test_exact_engine_equals_naive_solver(case, references):
    ref = references[case]
    res = _engine(*case, exact=True)
    assert res.ok, res.reason
    assert not ref["snaps"] and ref["stop"] == "recovered"
    assert res.pull_off == pytest.approx(ref["pull_off"], rel=1e-9)
    assert res.a_pulloff == pytest.approx(ref["a_pulloff"], abs=1e-8)
    assert res.a0_result == pytest.approx(ref["a0"], abs=1e-9)
    P, P_ref = _common(res, ref)
    np.testing.assert_allclose(P, P_ref, rtol=0, atol=1e-8)


@pytest.mark.parametrize("rtol", [1e-4, 1e-6])
@pytest.mark.parametrize("case", CASES)
def test_prony_engine_within_its_tolerance_of_naive_solver(case, rtol, references):
    ref = references[case]
    res = _engine(*case, prony_rtol=rtol)
    assert res.ok, res.reason
    assert res.prony_error <= rtol
    assert res.pull_off == pytest.approx(ref["pull_off"], rel=rtol)
    P, P_ref = _common(res, ref)
    assert np.max(np.abs(P - P_ref)) <= 2 * rtol * np.max(np.abs(P_ref))
