"""The error estimate of a BEM result (sweep.engine.resolution, issue 21 item 1): the pull-off
change at half the resolution in space and time, plus the Prony fit's error; the a-priori
bound where the cheaper solve fails. Its coverage of the true error on a random sample is
measured by `make error-coverage` (sweep.bench.error_coverage) and checked on a small
seeded sample here."""
from __future__ import annotations

import math

import pytest

from sweep import Numerics, Result, Scene
from sweep.engine.bem import simulate
from sweep.engine.resolution import (RESOLUTION_ERROR_K, coarser, estimate_error,
                                     resolution_error)

SCENE = Scene(n=0.8, k=0.1, mu=3.24, a0=2.0, rate=10.0)


def _ok(numerics, pull_off, prony_error=1e-5, spacing=0.01):
    return Result(scene=SCENE, numerics=numerics, status="ok", pull_off=pull_off,
                  prony_error=prony_error, spacing=spacing)


def test_coarser_halves_the_resolution_in_space_and_time():
    num = Numerics.preset("balanced", da_max_pulloff=None)
    c = coarser(num)
    assert c.band_resolution == num.band_resolution / 2 and c.step == 2 * num.step
    assert c.da_max == num.da_max                # in spacings: doubles in a_ref with them
    assert c.prony_rtol == num.prony_rtol and c.pull_off_rtol == 0.0 and c.zone_nodes == 0.0


def test_coarser_takes_the_pull_off_bound_throughout_never_finer_than_the_solve():
    """With a smaller radius change near the pull-off, the cheaper solve takes that bound
    throughout, but not below da_max / factor of its spacings: in a_ref its radius change
    per step stays at least the finer solve's."""
    num = Numerics.preset("balanced", da_max=1.0, da_max_pulloff=0.6)
    c = coarser(num)
    assert (c.da_max, c.da_max_pulloff) == (0.6, None)
    c = coarser(num, math.sqrt(2.0))
    assert c.da_max == pytest.approx(1.0 / math.sqrt(2.0)) and c.da_max_pulloff is None
    assert coarser(Numerics.preset("balanced", da_max=0.5, da_max_pulloff=0.6)).da_max == 0.5


def test_estimate_is_the_change_plus_the_prony_error():
    num = Numerics.preset("balanced")
    res = _ok(num, 2.0)
    estimate_error(res, 0.1, lambda n: _ok(n, 2.01))
    assert res.error_estimate == pytest.approx(0.005 + 1e-5, rel=1e-12) and res.ok
    res = _ok(num, 2.0)
    estimate_error(res, 0.1, lambda n: _ok(n, 2.05))
    assert res.status == "failed" and res.reason.startswith("unresolved: the pull-off moves by")


def test_a_priori_bound_where_the_cheaper_solve_fails():
    num = Numerics.preset("balanced")
    res = _ok(num, 2.0, spacing=0.004)
    failed = Result(scene=SCENE, numerics=num, status="failed", reason="time budget: ...")
    estimate_error(res, 0.1, lambda n: failed)
    assert res.error_estimate == pytest.approx(RESOLUTION_ERROR_K * 0.04**2 + 1e-5)
    assert res.ok and "error estimate a priori" in res.reason and "time budget" in res.reason
    assert resolution_error(0.004, 0.1) == RESOLUTION_ERROR_K * 0.04**2


def test_no_estimate_without_a_tolerance():
    res = _ok(Numerics.preset("balanced", pull_off_rtol=0.0), 2.0)
    estimate_error(res, 0.1, lambda n: pytest.fail("no second solve without a tolerance"))
    assert math.isnan(res.error_estimate)


@pytest.mark.parametrize("kw", [
    dict(n=2.261, k=0.00415, mu=1.579, a0=0.5677, rate=1.138e8),   # narrow band, fast: h^2
    dict(n=0.528, k=0.5733, mu=0.03773, a0=3.0, rate=9.757),        # DMT side: Prony, steps
])
def test_the_estimate_covers_the_error_against_a_finer_run(kw):
    """Two scenes of the coverage sample where the former estimate (0.3 (spacing/l0)^2)
    fell 10-1000x short: the fast preset's estimate now covers its error against the
    accurate preset refined further (band_resolution 60, step 0.025, Prony 1e-7), and is
    not looser than 30x (the first scene's fast error, 2.9 %, is at its 3 % tolerance: the
    fast preset itself fails it as unresolved)."""
    scene = Scene(**kw)
    ref = simulate(scene, Numerics.preset("accurate", band_resolution=60.0, step=0.025,
                                          da_max=0.15, prony_rtol=1e-7, tol=1e-10,
                                          pull_off_rtol=0.0, max_nodes=5000))
    res = simulate(scene, Numerics.preset("fast", pull_off_rtol=1.0))   # the estimate, not the verdict
    assert ref.ok and res.ok, (ref.reason, res.reason)
    true = abs(res.pull_off / ref.pull_off - 1.0)
    assert true <= res.error_estimate <= 30 * max(true, 1e-6), (true, res.error_estimate)
