"""Stability at the extremes of (n, k, rate, a0, mu) (issue 10, item 5): every scene ends ok
with a finite pull-off inside bounds that do not come from the BEM (the relaxed elastic
pull-off of the quasi-static branch below, and exactly at the slowest rate; 2/k or the
cohesive limit of a frozen contact above; sweep.bench.extremes), or failed with a reason.

The quick suite runs a covering subset (every value of every axis); the full product
(144 scenes, minutes) is marked slow and printed by `make extremes`.
"""
import math

import pytest

from sweep.bench import extremes
from sweep import Numerics, Scene
from sweep.engine.models import simulate


def _check(d):
    num = Numerics.preset("balanced", time_budget_s=extremes.TIME_BUDGET_S)
    res = simulate(Scene(**d), num)
    verdict = extremes.judge(d, res)
    assert not verdict.startswith("WRONG"), (d, verdict)
    if res.status == "ok":
        assert math.isfinite(res.pull_off)
    else:
        assert res.reason and math.isnan(res.pull_off)
    return res


@pytest.mark.parametrize("d", extremes.QUICK, ids=lambda d: "-".join(f"{v:g}" for v in d.values()))
def test_covering_subset(d):
    _check(d)


def test_covering_subset_covers_every_value():
    for name, values in (("n", extremes.N_VALUES), ("k", extremes.K_VALUES),
                         ("rate", extremes.RATES), ("a0", extremes.A0_VALUES),
                         ("mu", extremes.MU_VALUES)):
        assert {d[name] for d in extremes.QUICK} == set(values), name


def test_known_limits_of_the_bounds():
    # relaxed elastic from a large contact: DMT 2 at mu -> 0, JKR 1.5 at high mu
    assert extremes.relaxed_pull_off(0.01, 15.0) == pytest.approx(2.0, rel=2e-3)
    assert extremes.relaxed_pull_off(100.0, 15.0) == pytest.approx(1.5, rel=2e-3)
    # 2/k where the contact is small; the frozen flat punch's cohesive limit where it is large
    assert extremes.upper_bound(10.0, 0.1, 0.55) == 20.0
    assert extremes.upper_bound(0.1, 0.5, 15.0) > 4.0


@pytest.mark.slow
@pytest.mark.parametrize("d", extremes.all_scenes(),
                         ids=lambda d: "-".join(f"{v:g}" for v in d.values()))
def test_full_product(d):
    _check(d)
