"""Stability at the extremes of (n, k, rate, a0, mu) (issue 10, item 5): every scene ends ok
with a finite pull-off inside bounds that do not come from the BEM (the relaxed elastic
pull-off of the quasi-static branch below, and exactly at the slowest rate; 2/k or the
cohesive limit of a frozen contact above; sweep.bench.extremes), or failed with a reason.

The quick suite runs a covering subset (every value of every axis); the full product
(144 scenes, minutes) is marked slow and printed by `make extremes`. Each row is classed ok /
physically refused / failed / wrong / error (classify, tested on fabricated results), and
seeded random samples drawn log-uniformly across the limits Scene declares run with model
"auto" (issue 21, item 5): a handful in the quick suite, 60 in the slow one.
"""
import json
import math
from functools import lru_cache

import pytest

from sweep.bench import extremes
from sweep import Numerics, Scene
from sweep.scene import AXES
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


# -- classification of a row (sweep.bench.extremes.classify) --------------------------------
_D = dict(n=0.2, k=0.5, rate=1.0, a0=15.0, mu=0.1)


def _result(status="ok", reason="", pull_off=math.nan):
    from sweep.scene import Result
    return Result(scene=Scene(**_D), numerics=Numerics.preset("fast"), status=status,
                  reason=reason, pull_off=pull_off)


@pytest.mark.parametrize("res, cls", [
    (dict(pull_off=2.5), "ok"),
    (dict(status="failed", reason="no contact in the initial state: the relaxed state ..."),
     "refused"),
    (dict(status="failed", reason="no stable contact of radius 0.4"), "refused"),
    (dict(status="failed", reason="time budget 60 s exceeded after 1200 steps"), "failed"),
    (dict(status="failed", reason="InputError: a0 must be >= 0.5 (got 0.3)"), "failed"),
    (dict(pull_off=1e6), "wrong"),              # above 2/k and the cohesive limit
    (dict(pull_off=0.5), "wrong"),              # below the relaxed elastic pull-off
    (dict(pull_off=math.nan), "wrong"),
    (dict(pull_off=math.inf), "wrong"),
    (dict(status="failed"), "wrong"),           # failed without a reason
    (dict(status="maybe", pull_off=2.5), "wrong"),
    (dict(status="error", reason="TypeError: boom"), "error"),
], ids=lambda x: x if isinstance(x, str) else None)
def test_classify_each_class(res, cls):
    got, verdict = extremes.classify(_D, _result(**res))
    assert got == cls, verdict
    assert got in extremes.CLASSES
    assert verdict == "ok" if cls == "ok" else verdict != "ok"


def test_classify_keeps_judge_at_the_slowest_rate():
    d = dict(_D, rate=min(extremes.RATES))
    lo = extremes.relaxed_pull_off(d["mu"], d["a0"])
    assert extremes.classify(d, _result(pull_off=lo))[0] == "ok"
    assert extremes.classify(d, _result(pull_off=1.05 * lo))[0] == "wrong"


def test_counts_has_every_class():
    rows = [dict(cls="ok"), dict(cls="ok"), dict(cls="refused"), dict(cls="error")]
    assert extremes.counts(rows) == dict(ok=2, refused=1, failed=0, wrong=0, error=1)


def test_an_exception_escaping_simulate_is_an_error_row_and_exit_1(monkeypatch, tmp_path, capsys):
    def boom(scene, numerics=None):
        raise TypeError("boom")
    monkeypatch.setattr(extremes, "simulate", boom)
    row = extremes.run_scene(_D, "auto")
    assert row["cls"] == "error" and row["internal"]
    assert "TypeError: boom" in row["traceback"] and "Traceback" in row["traceback"]
    assert extremes._main(["--quick", "--model", "bem", "--out", str(tmp_path)]) == 1
    report = json.loads((tmp_path / "extremes.json").read_text())
    assert report["models"]["bem"]["counts"]["error"] == len(extremes.QUICK)
    assert report["preset"] == extremes.PRESET
    assert report["time_budget_s"] == extremes.TIME_BUDGET_S and report["date"]
    assert "internal error" in (tmp_path / "summary.md").read_text()
    assert "ERROR" in capsys.readouterr().err


def test_json_and_summary_of_a_clean_run(monkeypatch, tmp_path):
    def fake(scene, numerics=None):
        res = _result(status="failed", reason="no stable contact (fabricated)")
        res.model_used = "crack"
        return res
    monkeypatch.setattr(extremes, "simulate", fake)
    monkeypatch.setattr(extremes, "QUICK", extremes.QUICK[:2])
    assert extremes._main(["--quick", "--model", "bem", "auto", "--out", str(tmp_path)]) == 0
    report = json.loads((tmp_path / "extremes.json").read_text())
    assert list(report["models"]) == ["bem", "auto"]
    for m in report["models"].values():
        assert m["counts"] == dict(ok=0, refused=2, failed=0, wrong=0, error=0)
        assert [r["cls"] for r in m["rows"]] == ["refused", "refused"]
        assert m["rows"][0]["pull_off"] is None          # NaN written as null
    md = (tmp_path / "summary.md").read_text()
    assert "| bem | 0 | 2 | 0 | 0 | 0 | 2 |" in md


# -- seeded random samples across the declared limits (model "auto") -------------------------
#: the quick sample: a handful of scenes on the fast preset with a short budget
RANDOM_QUICK = dict(count=5, seed=20261125)
#: the larger sample (slow): counts are printed, failures must be physical
RANDOM_SLOW = dict(count=60, seed=21)


def test_random_scenes_are_inside_the_declared_limits():
    scenes = extremes.random_scenes(200, seed=1)
    for name in ("n", "k", "rate", "a0", "mu"):
        lo, hi = AXES[name].limits
        values = [d[name] for d in scenes]
        assert all(lo < v <= hi if AXES[name].lo_open else lo <= v <= hi for v in values), name
        # log-uniform: about half of them below the geometric middle of the sampled range
        lo_used = lo if lo > 0 else {"n": min(extremes.N_VALUES), "k": min(extremes.K_VALUES),
                                     "rate": min(extremes.RATES)}[name]
        below = sum(v < math.sqrt(lo_used * hi) for v in values) / len(values)
        assert 0.35 < below < 0.65, (name, below)
    for d in scenes:
        Scene(**d, model="auto")                          # every drawn scene is accepted
    assert extremes.random_scenes(3, seed=7) == extremes.random_scenes(3, seed=7)


def _check_random_row(row):
    """What must hold for every model and scene today: nothing escapes simulate, an ok row is
    finite and inside the physical bounds, a failed row has a reason."""
    assert row["cls"] != "error", (row["verdict"], row.get("traceback"))
    assert row["cls"] != "wrong", row["verdict"]
    if row["status"] == "ok":
        assert math.isfinite(row["pull_off"])
    else:
        assert row["status"] == "failed" and row["reason"]


def test_random_sample_auto_quick():
    num = Numerics.preset("fast", time_budget_s=8.0)
    for d in extremes.random_scenes(**RANDOM_QUICK):
        _check_random_row(extremes.run_scene(d, "auto", num))


@lru_cache(maxsize=None)
def _slow_rows():
    num = Numerics.preset("fast", time_budget_s=20.0)
    rows = extremes.run(extremes.random_scenes(**RANDOM_SLOW), num, model="auto")
    print("\nauto, seeded random sample:", extremes.counts(rows))
    for r in rows:
        if r["cls"] != "ok":
            print(f"  {r['cls']}: {extremes._scene_str(r)} ({r['model']}): {r['verdict']}")
    return tuple(rows)


@pytest.mark.slow
def test_random_sample_auto_large():
    rows = _slow_rows()
    for row in rows:
        _check_random_row(row)
    counts = extremes.counts(rows)
    assert sum(counts.values()) == RANDOM_SLOW["count"]


@pytest.mark.slow
@pytest.mark.xfail(strict=False, reason="a known hole of auto (issue 21; seed 21, 2026-11-25 "
                   "after the chooser: 53 ok, 6 physically refused, 1 failed): the BEM 'could "
                   "not reach the initial contact radius' at mu = 0.033, a0 = 0.50 (the DMT "
                   "side, where no other model answers)")
def test_random_sample_auto_fails_only_for_physical_reasons():
    bad = [(extremes._scene_str(r), r["model"], r["reason"]) for r in _slow_rows()
           if r["cls"] not in ("ok", "refused")]
    assert not bad, bad


def test_a_row_is_held_to_the_error_it_states():
    from sweep.scene import Result
    """The crack-front model's row at the slowest rate may differ from the relaxed elastic
    pull-off by the error it states (its measured difference from the BEM), not more."""
    d = dict(n=2.5, k=1e-4, rate=min(extremes.RATES), a0=15.0, mu=100.0)
    lo = extremes.relaxed_pull_off(100.0, 15.0)
    res = Result(scene=Scene(**d), numerics=Numerics.preset("fast"), status="ok",
                 pull_off=1.015 * lo)
    assert extremes.judge(d, res).startswith("WRONG")              # no stated error: 1 %
    res.error_estimate = 0.028
    assert extremes.judge(d, res) == "ok"
    res.pull_off = 1.03 * lo
    assert extremes.judge(d, res).startswith("WRONG")
