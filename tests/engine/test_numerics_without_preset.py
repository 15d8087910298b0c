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
HIGH_MU = dict(n=0.5, k=0.01, mu=300.0, a0=3.0, rate=1e3)     # beyond the BEM: crack


def test_uniform_nodes_resolves_none():
    assert NUM.mesh == "uniform" and NUM.nodes is None
    assert NUM.uniform_nodes == UNIFORM_NODES == 500
    assert Numerics(nodes=80).uniform_nodes == 80
    assert scene_mesh(NUM, 0.1, 2.0, 10.0).nodes == 500
    assert models.bem_node_budget(NUM) == 500
    # the error estimate's cheaper solve really is coarser (half the nodes), not the same mesh
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


# -- beyond the BEM's Tabor range, auto runs the crack-front model (issue 21 item 3) --------
@pytest.mark.parametrize("mu", [150.0, 2154.0, 1e5])
def test_auto_beyond_the_bem_range_runs_the_crack_front_model(mu):
    """mu = 2154 is PDMS-like with a physical h0 = 0.5 nm: once refused by the Scene
    ("mu must be in [0.01, 1000]"), now the crack-front model's, with its error stated."""
    from sweep.engine.problem import BEM_MU_RANGE

    scene = Scene(n=0.8, k=0.1, mu=mu, a0=3.0, rate=316.0, model="auto")
    assert models.choose_model(scene) == "crack"
    res = models.simulate(scene)
    assert res.model_used == "crack" and res.ok
    assert math.isfinite(res.pull_off) and 1.0 < res.pull_off < 20.0
    assert res.model_reason.startswith(
        f"auto: crack-front model, the mu -> infinity limit: mu = {mu:g} is beyond the BEM's "
        f"range [0.01, {BEM_MU_RANGE[1]:g}]")
    # its error is the envelope of the measurement held at its largest mu, stated in the row
    assert res.error_estimate == models.measured_error(
        "crack", BEM_MU_RANGE[1], models.amplification(res.pull_off)) > 0
    assert f"measured error {res.error_estimate:.2g}" in res.model_reason
    # the BEM itself refuses it with its reason (a failed row, not an exception)
    bem = models.simulate(Scene(n=0.8, k=0.1, mu=mu, a0=3.0, rate=316.0, model="bem"))
    assert bem.status == "failed" and bem.reason


def test_auto_within_the_bem_range_keeps_an_empty_reason():
    res = models.simulate(Scene(**VISCO, model="auto"), Numerics.preset("fast"))
    assert res.model_used == "bem" and res.ok and res.reason == ""
    assert res.model_reason.startswith("auto: BEM on the graded mesh")
