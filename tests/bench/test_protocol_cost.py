"""What the test as run costs (issue 36 item 5, `make protocol-cost`): the table the
comparison builds is the MPL's own series, and the committed measurement's ratios are its
walls' (results/protocol/cost.json)."""
from __future__ import annotations

import json
from pathlib import Path

import pytest

from sweep.bench import protocol_cost
from sweep.engine.problem import prepare
from sweep.scene import Numerics, Scene

ROOT = Path(__file__).resolve().parents[2]
COST = ROOT / "results" / "protocol" / "cost.json"


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
    assert len(doc["rows"]) == len(protocol_cost.SCENES)
    for row in doc["rows"]:
        assert row["status"] == "ok"
        assert row["ratio"] == pytest.approx(row["wall_s"] / row["relaxed_wall_s"])
        assert row["ratio_two_relaxed"] == pytest.approx(
            row["wall_s"] / (row["relaxed_wall_s"] + row["approach_relaxed_wall_s"]))
    for row in doc["table_rows"]:
        assert row["prony_terms"] == row["mpl_prony_terms"]
        assert row["pull_off"] == pytest.approx(row["mpl_pull_off"], rel=1e-4)
        assert row["ratio"] == pytest.approx(row["wall_s"] / row["mpl_wall_s"])
