"""The estimate's pair as an extrapolation pair (issue 33 item 2): the summary arithmetic on
rows of known convergence, and the committed measurement
(results/error_coverage/extrapolation.json and extrapolation_seed11.json, `make
extrapolation`) recomputes from its rows."""
from __future__ import annotations

import json
from pathlib import Path

import pytest

from sweep.bench import extrapolation

ROOT = Path(__file__).resolve().parents[2]
COMMITTED = [ROOT / "results" / "error_coverage" / name
             for name in ("extrapolation.json", "extrapolation_seed11.json")]


def _row(error_h, order, preset="balanced", reference=1.0, prony=0.0):
    """A scene whose pull-off converges as P(h) = ref (1 + error_h (h/h_fine)^order)."""
    p = [reference * (1.0 + error_h * 2.0 ** (order * j)) for j in range(3)]
    return {"preset": preset, "status": "ok", "reference": reference, "pull_off": p[0],
            "prony_error": prony, "error_estimate": abs(p[0] - p[1]) / p[0] + prony,
            "coarse": [(10.0, True, p[1]), (5.0, True, p[2])]}


def test_second_order_rows_extrapolate_exactly():
    rows = [_row(1e-4, 2.0), _row(-3e-4, 2.0), _row(2e-3, 2.0)]
    s = extrapolation.summarize(rows)["balanced"]
    assert s["scenes"] == 3
    assert s["observed_order"]["median"] == pytest.approx(2.0, rel=1e-6)
    assert s["median_error_extrapolated_p2"] < 1e-9 * s["median_error"]
    assert s["improved_p2"] == 1.0
    # the pair's change is 3 times a second-order error: covered, looseness 3
    assert s["estimate_pair"]["coverage"] == 1.0
    assert s["estimate_pair"]["median_looseness"] == pytest.approx(3.0, rel=1e-2)


def test_a_first_order_row_is_not_covered_by_the_extrapolation_estimate():
    """First order: P_x (p = 2) keeps two thirds of the error, which the correction's size
    (a third of it) does not cover; the pair's change equals the error of P_h."""
    s = extrapolation.summarize([_row(1e-3, 1.0)])["balanced"]
    assert s["observed_order"]["median"] == pytest.approx(1.0, rel=1e-6)
    assert s["median_error_extrapolated_p2"] == pytest.approx(2e-3 / 3.0, rel=1e-2)
    assert s["estimate_extrapolated"]["coverage"] == 0.0
    assert s["estimate_pair"]["median_looseness"] == pytest.approx(1.0, rel=1e-2)


def test_a_crossing_pair_is_caught_by_the_third_solve():
    """P_h and P_2h on either side of the limit, close together: the pair's change misses the
    error, the coarser pair's (over 4) does not."""
    row = {"preset": "fast", "status": "ok", "reference": 1.0, "pull_off": 1.0 + 1e-3,
           "prony_error": 0.0, "error_estimate": 2e-4,
           "coarse": [(5.0, True, 1.0 + 8e-4), (2.5, True, 1.0 - 2e-2)]}
    s = extrapolation.summarize([row])["fast"]
    assert s["estimate_pair"]["coverage"] == 0.0
    assert s["estimate_three_resolutions"]["coverage"] == 1.0


def test_rows_without_a_third_solve_are_left_out():
    row = _row(1e-3, 2.0)
    row["coarse"] = row["coarse"][:1]
    assert extrapolation.summarize([row, _row(1e-3, 2.0, preset="fast")]).keys() == {"fast"}


@pytest.mark.parametrize("path", COMMITTED, ids=lambda p: p.name)
def test_the_committed_measurement_recomputes_from_its_rows(path):
    doc = json.loads(path.read_text())
    assert doc["command"] == "make extrapolation"
    summary = extrapolation.summarize(doc["rows"])
    for preset, s in summary.items():
        stored = doc["summary"][preset]
        assert s["scenes"] == stored["scenes"] >= 15
        for key in ("median_error", "median_error_extrapolated_p2", "improved_p2"):
            assert s[key] == pytest.approx(stored[key], rel=1e-12)


def test_crossing_cost_runs_both_and_restores_the_gate(tmp_path):
    """--crossing-cost times each scene with and without the check and leaves the gate as it
    found it."""
    from sweep.engine import resolution

    config = tmp_path / "c.yaml"
    config.write_text("name: c\ngrid: {n: 0.8, k: 0.1, mu: 3.24, a0: 1.5, rate: [1.0, 100.0]}\n"
                      "numerics: {preset: fast}\noutput: c.h5\n")
    gate = resolution.CROSSING_GATE
    c = extrapolation.crossing_cost(str(config))
    assert resolution.CROSSING_GATE == gate
    assert c["scenes"] == 2 and c["wall_with_s"] > 0 and c["wall_without_s"] > 0
    assert 0 <= c["estimates_raised"] <= 2
