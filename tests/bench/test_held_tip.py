"""The held-tip scan's sample and summary (``make held-tip`` runs it whole)."""
import math

from sweep.bench.held_tip import RANGES, scenes, summarize


def test_the_sample_is_seeded_in_its_ranges_with_both_kinds():
    a, b = scenes(5, 5, seed=3), scenes(5, 5, seed=3)
    assert a == b and len(a) == 10 and a != scenes(5, 5, seed=4)
    for d in a[:5]:
        assert "a0" in d and "preload" not in d
    for d in a[5:]:
        assert "a0" not in d and d["approach_rate"] == d["rate"]
        assert RANGES["preload"][0] <= d["preload"] <= RANGES["preload"][1]
    for d in a:
        for q in ("n", "k", "mu", "rate"):
            lo, hi = RANGES[q]
            assert lo * (1 - 1e-3) <= d[q] <= hi * (1 + 1e-3), (q, d[q])


def test_the_summary_counts_misses_covers_and_held_tips():
    def req(status, error, estimate, travel, reason=""):
        return {"status": status, "error": error, "error_estimate": estimate, "travel": travel,
                "wall_s": 0.1, "reason": reason}
    ok_ref = {"status": "ok"}
    rows = [
        {"kind": "relaxed", "reference": ok_ref, "0.03": req("ok", 0.05, 0.01, 0.5),
         "0.01": req("failed", math.nan, 0.02, math.nan, "unresolved: ...")},
        {"kind": "relaxed", "reference": ok_ref, "0.03": req("ok", 0.001, 0.01, 4.0),
         "0.01": req("ok", 0.002, 0.001, 6.0)},
        {"kind": "protocol", "reference": {"status": "failed"}, "0.03": req("ok", 0.2, 0.1, 0.1),
         "0.01": req("ok", 0.2, 0.1, 0.1)},
    ]
    s = summarize(rows)
    assert s["relaxed 0.03"] == {**s["relaxed 0.03"], "scenes": 2, "ok": 2, "missed": 1,
                                 "not_covered": 1, "held": 1, "least_travel": 0.5,
                                 "worst_error": 0.05}
    assert s["relaxed 0.01"]["unresolved"] == 1 and s["relaxed 0.01"]["not_covered"] == 1
    assert s["protocol 0.03"]["scenes"] == 0      # no reference: not counted
