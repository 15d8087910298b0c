"""Explicit numerics without a preset work with every model (issue 21 item 4).

``numerics: {time_budget_s: 15}`` is a uniform mesh with ``nodes`` unset (500 nodes); "auto"
compared the node count it needs with ``nodes`` (None) and every scene raised TypeError.
"""
from __future__ import annotations

import math

import pytest

from sweep.engine import models
from sweep.engine.mesh import scene_mesh
from sweep.engine.resolution import coarser
from sweep.scene import UNIFORM_NODES, Numerics, Scene

NUM = Numerics.from_dict({"time_budget_s": 15})      # fields, no preset
VISCO = dict(n=0.8, k=0.1, mu=3.24, a0=2.0, rate=10.0)
ELASTIC = dict(n=0.8, k=1.0, mu=3.24, a0=2.0, rate=10.0)
HIGH_MU = dict(n=0.5, k=0.01, mu=30.0, a0=3.0, rate=1e3)


def test_uniform_nodes_resolves_none():
    assert NUM.mesh == "uniform" and NUM.nodes is None
    assert NUM.uniform_nodes == UNIFORM_NODES == 500
    assert Numerics(nodes=80).uniform_nodes == 80
    assert scene_mesh(NUM, 0.1, 2.0, 10.0).nodes == 500
    assert models.bem_node_budget(NUM) == 500
    # the error indicator's cheaper solve really is coarser (half the nodes), not the same mesh
    assert coarser(NUM).nodes == 250 and coarser(Numerics(nodes=80)).nodes == 40


@pytest.mark.parametrize("model, kw, expect", [
    ("auto", VISCO, "bem"), ("auto", ELASTIC, "elastic"), ("auto", HIGH_MU, "crack"),
    ("bem", VISCO, "bem"), ("bem", ELASTIC, "elastic"), ("crack", VISCO, "crack"),
    ("crack", HIGH_MU, "crack"), ("pb", VISCO, "pb"), ("elastic", ELASTIC, "elastic")])
def test_every_model_runs_with_numerics_without_preset(model, kw, expect):
    res = models.simulate(Scene(**kw, model=model), NUM)
    assert res.model_used == expect
    assert res.status == "ok", res.reason
    assert math.isfinite(res.pull_off) and res.pull_off > 0


def test_choose_model_with_uniform_numerics():
    assert models.choose_model(Scene(**VISCO), NUM) == "bem"
    assert models.choose_model(Scene(**HIGH_MU), NUM) == "crack"
