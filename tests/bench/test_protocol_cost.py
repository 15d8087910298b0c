"""What the test as run costs (issue 36 item 5, `make protocol-cost`): the table the
comparison builds is the MPL's own series, and the committed measurement's ratios are its
walls' (results/protocol/cost.json)."""
from __future__ import annotations

import json
from types import SimpleNamespace
from pathlib import Path

import pytest

from sweep.bench import protocol_cost
from sweep.engine.problem import prepare
from sweep.scene import Numerics, Scene

ROOT = Path(__file__).resolve().parents[2]
COST = ROOT / "results" / "protocol" / "cost.json"


def test_crack_travel_sums_the_contact_radius_path_by_phase():
    # a protocol's records: approach 1 -> 2 (travel 1), dwell 2 -> 2.5 (0.5), retraction
    # 2.5 -> 1 -> 1.25 (1.75); a relaxed start's records carry no phase: all retraction
    res = SimpleNamespace(trajectory={"a": [1.0, 2.0, 2.5, 1.0, 1.25],
                                      "phase": [0, 0, 1, 2, 2]})
    assert protocol_cost.crack_travel(res) == pytest.approx(
        {"approach": 1.0, "dwell": 0.5, "retract": 1.75})
    res.trajectory = {"a": [2.0, 1.5, 1.0]}
    assert protocol_cost.crack_travel(res) == pytest.approx(
        {"approach": 0.0, "dwell": 0.0, "retract": 1.0})


def test_the_bench_scenes_protocol_is_the_vs_numpy_scenes():
    from sweep.bench.tradeoff import VS_NUMPY_SCENES
    bench = protocol_cost.bench_scenes()
    assert len(bench) == len(VS_NUMPY_SCENES)
    for (_, fields), scene in zip(bench, VS_NUMPY_SCENES.values()):
        assert "delta0" not in fields and fields["approach_rate"] == fields["rate"] == scene["rate"]
        assert {k: fields[k] for k in ("n", "k", "mu")} == {k: scene[k] for k in ("n", "k", "mu")}
        Scene(**fields)                       # a valid protocol scene


def test_the_table_holds_the_mpl_scenes_own_series():
    mpl = Scene(mu=protocol_cost.MU, a0=protocol_cost.TABLE_A0, n=0.8, k=0.1, rate=1.0)
    table = protocol_cost.mpl_series_table(mpl)
    pb = prepare(mpl, Numerics.preset("balanced"))
    assert table["c"] == pytest.approx(pb.prony_weights.tolist(), rel=0, abs=0)
    scene = Scene(mu=protocol_cost.MU, a0=protocol_cost.TABLE_A0, n=0.8, rate=1.0,
                  material=table)
    # its k, 1 - sum(c), is the fitted series' glassy compliance: the MPL's k to the fit's
    # accuracy on the scene's window (measured 0.4 %)
    assert scene.table is not None and scene.k == pytest.approx(mpl.k, rel=1e-2)


def test_the_committed_ratios_are_the_walls():
    doc = json.loads(COST.read_text())
    assert doc["command"] == "make protocol-cost"
    names = [name for name, _ in [*protocol_cost.SCENES, *protocol_cost.bench_scenes()]]
    assert [row["scene"] for row in doc["rows"]] == names
    for row in doc["rows"]:
        assert row["status"] == "ok"
        assert row["ratio"] == pytest.approx(row["wall_s"] / row["relaxed_wall_s"])
        assert row["ratio_two_relaxed"] == pytest.approx(
            row["wall_s"] / (row["relaxed_wall_s"] + row["approach_relaxed_wall_s"]))
        assert row["travel_ratio"] == pytest.approx(
            sum(row["travel"].values()) / row["relaxed_travel"])
        assert row["cost_per_travel_ratio"] == pytest.approx(row["ratio"] / row["travel_ratio"])
        assert row["solve_ratio"] == pytest.approx(
            row["solve_wall_s"] / row["relaxed_solve_wall_s"])
    for row in doc["table_rows"]:
        assert row["prony_terms"] == row["mpl_prony_terms"]
        assert row["pull_off"] == pytest.approx(row["mpl_pull_off"], rel=1e-4)
        assert row["ratio"] == pytest.approx(row["wall_s"] / row["mpl_wall_s"])
