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


# -- a smaller radius change per step near the pull-off (Numerics.da_max_pulloff) -------------
from sweep.kernels.solve import Records, near_pulloff  # noqa: E402


def _records(t, P, a):
    t, P, a = (np.asarray(x, float) for x in (t, P, a))
    return Records(t, -t, P, a, 0.0 * a, np.zeros(3))


def test_near_pulloff_predicts_the_minimum_of_a_parabola():
    """P = (t - 10)^2 sampled at t = 0, 1, 2, ...: from the records at t_k - 2, t_k - 1,
    t_k the Newton step on dP/dt = 0 puts the minimum at t = 10 exactly; with the tip
    receding at speed 0.1 the travel left is 0.1 (10 - t_k), so a zone of 0.35 a_ref counts
    the minimum near from t_k = 7 on (travel 0.3) and not at t_k = 6 (0.4)."""
    t = np.arange(20.0)
    P, a = (t - 10.0) ** 2, 5.0 - 0.1 * t
    rec = _records(t, P, a)
    near = [near_pulloff(rec, n, 0.35) for n in range(3, 20)]   # after record n - 1
    assert near == [n - 1 >= 7 for n in range(3, 20)]
    assert near_pulloff(rec, 1, 0.0) and near_pulloff(rec, 2, 0.0)  # the first two steps
    # a tip at rest (or advancing) is never near by travel; a rising load always is
    still = _records(t, P, 0.0 * t + 5.0)
    assert not near_pulloff(still, 5, 1e9) and near_pulloff(still, 13, 0.0)


@pytest.mark.parametrize("scene", [Scene(n=0.4, k=0.1, mu=3.24, a0=4.5, rate=1.0),
                                   Scene(n=0.8, k=0.1, mu=3.24, a0=1.5, rate=1.0)],
                         ids=["a0_4.5", "a0_1.5"])
def test_finer_steps_near_the_pull_off_give_the_crack_speed_of_finer_steps(scene):
    """With da_max 1 spacing the crack speed at pull-off is read from records a spacing
    apart; bounded to 0.6 spacing near the minimum (da_max_pulloff) it is read as from
    the balanced preset's steps, for a few per cent more steps than da_max 1 alone.
    Independent value: the same mesh at da_max 0.1 and step 0.05 h0."""
    def run(**kw):
        return solver.simulate(scene, Numerics.preset("balanced", pull_off_rtol=0.0, **kw))

    fine = run(da_max=0.1, step=0.05, da_max_pulloff=None)
    coarse = run(da_max=1.0, da_max_pulloff=None)
    near = run(da_max=1.0, da_max_pulloff=0.6)
    assert fine.ok and coarse.ok and near.ok
    err = {name: abs(r.crack_speed / fine.crack_speed - 1)
           for name, r in (("coarse", coarse), ("near", near))}
    assert err["coarse"] > 4e-3 and err["near"] < 1e-3, err
    assert abs(near.pull_off / fine.pull_off - 1) < 1e-3
    assert coarse.steps < near.steps < 1.3 * coarse.steps
    # the bound holds on the records the crack-speed fit reads, and not before
    a = near.trajectory["a"]
    da = np.abs(np.diff(a)) / near.spacing
    fit = np.abs(a[1:] - near.a_pulloff) <= 3 * near.spacing
    assert da[fit].max() <= 0.6 * (1 + 1e-9) and da[~fit].max() > 0.7


def test_da_max_pulloff_is_checked():
    from sweep.errors import InputError
    with pytest.raises(InputError, match="da_max_pulloff"):
        Numerics(da_max_pulloff=0.0)
    assert Numerics().da_max_pulloff is None
