"""The adaptive time steps keep the pull-off within the preset's tolerance.

Independent value: the same scene and mesh at ten times smaller steps (step and da_max
divided by 10, no growth beyond the step: sweep.engine.bem.STEP_TOL = 0).
"""
import dataclasses

import numpy as np
import pytest

from sweep.engine import bem as solver
from sweep.scene import Numerics, Scene

SCENES = [Scene(n=0.8, k=0.2, mu=3.24, a0=1.5, rate=10.0),
          Scene(n=0.4, k=0.1, mu=3.24, a0=2.0, rate=10**0.5)]
#: share of the preset's pull_off_rtol the time stepping may use
TIME_SHARE = 0.1


@pytest.mark.parametrize("preset", ["fast", "balanced"])
@pytest.mark.parametrize("scene", SCENES, ids=["n0.8", "n0.4"])
def test_adaptive_steps_keep_the_pull_off_of_ten_times_smaller_steps(preset, scene, monkeypatch):
    num = Numerics.preset(preset)
    res = solver.simulate(scene, dataclasses.replace(num, pull_off_rtol=0.0))
    monkeypatch.setattr(solver, "STEP_TOL", 0.0)
    fine = solver.simulate(scene, dataclasses.replace(num, pull_off_rtol=0.0,
                                                      step=num.step / 10,
                                                      da_max=num.da_max / 10))
    assert res.ok and fine.ok
    assert res.steps < fine.steps / 4
    assert abs(res.pull_off / fine.pull_off - 1) < TIME_SHARE * num.pull_off_rtol
    # the run stopped past the minimum: the load recovered after it
    P = res.trajectory["P"]
    assert P[-1] > P.min() and np.argmin(P) < len(P) - 3
