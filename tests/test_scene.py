"""sweep.scene.Result prints as a one-line summary, never its trajectory arrays."""
from __future__ import annotations

import numpy as np

from sweep.scene import Numerics, Result, Scene

SCENE = Scene(n=0.8, k=0.1, mu=3.24, rate=10.0, a0=3.0, model="crack")


def _result(points: int, **kw) -> Result:
    rng = np.random.default_rng(0)
    traj = {name: rng.random(points) for name in ("t", "delta", "P", "a", "a_inner")}
    return Result(scene=SCENE, numerics=Numerics.preset("fast"), trajectory=traj, **kw)


def test_a_result_prints_its_summary_not_its_arrays():
    res = _result(5000, status="ok", pull_off=4.08732, crack_speed=0.705092, steps=4999,
                  model_used="crack")
    text = repr(res)
    assert str(res) == text and "\n" not in text
    assert len(text) < 200                       # the 5 arrays of 5000 floats: ~100 kB
    for part in ("Result(ok:", "pull_off=4.08732", "crack_speed=0.705092", "model=crack",
                 "steps=4999", "trajectory=5000 points", "n=0.8", "rate=10", "a0=3"):
        assert part in text, part
    assert "array" not in text and "0." + "0" * 5 not in text


def test_a_failed_result_prints_its_reason_shortened():
    res = _result(0, status="failed", reason="Newton failure " + "x" * 300)
    text = repr(res)
    assert text.startswith("Result(failed (Newton failure x") and "...)" in text
    assert "pull_off=nan" in text and "trajectory=0 points" in text
    assert "model=crack" in text                 # the model asked for, none recorded
    assert len(text) < 260


def test_a_result_in_a_list_prints_short():
    res = _result(2000, status="ok", pull_off=2.0)
    assert len(repr([res, res])) < 2 * 200
